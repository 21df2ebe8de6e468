// What refining one frame will take, known before the work: how many vertices get a surface
// Gaussian, what each camera sees, how many pairs of Gaussians the energy will evaluate, and a
// forecast of the peak memory and of the time of the frame.
//
// The pair lists dominate both for any but the smallest problems (8 bytes per pair, tens of
// millions of pairs when the Gaussians are large against the image), and their length depends on
// sigma_hat, k_max and the texture, so the forecast counts them: it builds the frame's image
// Gaussians and the pairs of a sample of the surface Gaussians (every n-th, enough for a count
// within a few per cent), without keeping them. With the detail stage a frame's memory peaks
// either while its surface Gaussians' energy is built or in the detail stage, which reuses that
// energy's memory once it is freed, and the forecast is the larger. The bytes per item
// (problem_size.cc) were fitted to the peak RSS of refinements of the synthetic captures, the
// Middlebury temple and Sceaux (at two resolutions), measured with bench/memory_forecast.sh on 2
// cores; a machine with many more cores keeps more per-thread
// memory (stacks, allocator arenas). The forecast is that of the configured level: the coarser
// levels of a coarse-to-fine schedule are solved before it and freed, and measured no higher
// (synth_skirt and the temple with refine.coarse_to_fine.levels 2: 3 % and 2 % above the
// forecast), but they add their time, which the time forecast leaves out.
#ifndef FINECAP_REFINE_PROBLEM_SIZE_H_
#define FINECAP_REFINE_PROBLEM_SIZE_H_

#include <vector>

#include "finecap/io/capture.h"
#include "finecap/measure/heldout_score.h"
#include "finecap/refine/refine.h"
#include "finecap/util/memory.h"

namespace finecap {

struct ProblemSize {
  int num_fine_vertices = 0;     // After subdivision.
  int num_refined_vertices = 0;  // Of those, the ones to refine (the vertex mask's, or all).
  // Refined vertices that get a surface Gaussian: some camera sees them (within the view-angle
  // cap and not occluded) and they have a reference colour.
  int num_surface_gaussians = 0;
  // Refined vertices that no camera sees (ComputeFrameVisibility, within the fallback view
  // angle where the similarity takes one): they keep the input surface.
  int num_unseen_refined_vertices = 0;
  // Refined vertices whose cameras alone would let them be refined with confidence: a view
  // confidence (ViewConfidence: enough cameras, at what angles, near enough to each other) of at
  // least kConfidentAt. The texture can only lower a vertex's confidence further, so fewer than
  // half of them means a capture too sparse to be refined usefully, whatever it shows.
  int num_well_seen_refined_vertices = 0;
  // Per camera, the fine vertices it sees (refined or not): 0 marks a camera that sees nothing.
  std::vector<int> visible_per_camera;
  long num_image_gaussians = 0;  // Over every camera.
  double num_pairs = 0.0;        // Estimated (a sample of the surface Gaussians, scaled).
  double num_pixels = 0.0;       // Over every camera.
  // Surface Gaussian and camera pairs that see each other: the residual blocks of the solve.
  long num_observations = 0;
  // With the detail stage (ConsensusOptions::sample_spacing): the surface samples, and the
  // samples a patch holds (of a regular vertex's).
  double num_surface_samples = 0.0;
  int samples_per_patch = 0;

  // Forecast peak resident memory of a run refining frames like this one, MB.
  double peak_memory_mb = 0.0;
  // The same were every frame to widen its search range as far as the plane sweep may
  // (SweepOptions::widen_share: k_max doubled up to max_widenings times, to
  // EnergyOptions::kLargestKMax at most): that range, metres, and the forecast peak with it (the
  // pairs and the colour tables grow with the range). Equal to k_max and peak_memory_mb when the
  // sweep does not widen. Whether a frame widens is known only once its sweep has run, so a run
  // is refused on peak_memory_mb alone, and told when the widest range might not fit.
  double widest_k_max = 0.0;
  double widest_peak_memory_mb = 0.0;
  // Forecast time of one frame, seconds, on the machine the constants were measured on (2 idle
  // cores), the held-out score included once AddHeldOutScoring has added it: a rough figure,
  // within 0.5 to 2 times the wall time on the captures that bench/memory_forecast.sh covers.
  double seconds_per_frame = 0.0;
};

// The problem of refining `frame` (coarse mesh, cameras, images) with `model`, `colors` and
// `options` (whose lengths should be resolved: scene_scale.h), in a run of `num_frames` frames
// like it: with more than one, the frames ahead are read and prepared while one is solved (one
// with the detail stage, two without), and the memory forecast holds them too. Builds the frame's
// image Gaussians and visibility, so it costs a few seconds on a large rig, and keeps none of it.
// `undistorted_pixels`: the pixels of the cameras whose images are undistorted as they are read
// (UndistortedPixels), whose maps are held for the whole run.
ProblemSize EstimateProblemSize(const SequenceModel& model, const ReferenceColors& colors,
                                const FrameInput& frame, const RefineOptions& options,
                                int num_frames = 1, double undistorted_pixels = 0.0);

// Adds to `size` the time of scoring each frame in the `held_out` views (ScoreHeldOutViews of
// three surfaces, each warping in the `neighbours` nearest of `num_training` training views):
// at full resolution it is a large part of a frame.
void AddHeldOutScoring(const std::vector<CalibratedImage>& held_out, int num_training,
                       int neighbours, ProblemSize* size);

// The pixels of `capture`'s cameras that have lens distortion, every one, held out or not: their
// images are undistorted as they are read.
double UndistortedPixels(const Capture& capture);

// Throws Error, naming the forecast peak memory and what to lower, when `size`'s forecast (of a
// run of `num_frames` frames) exceeds `max_memory_mb` (0: no limit of its own) or `available`: a
// run that the kernel would kill halfway, or that would push the machine into swap, is better
// refused before it starts. The forecast is good to about 25 % (problem_size.cc), so a run
// forecast just above the limit may have fitted, and one just below may not.
void RequireMemoryFor(const ProblemSize& size, int num_frames, const RefineOptions& options,
                      int max_memory_mb, const AvailableMemory& available);

// The memory a run may take, MB: `max_memory_mb` when it is set (above 0) and below what is
// `available`, else what is available.
double MemoryLimitMb(int max_memory_mb, const AvailableMemory& available);

}  // namespace finecap

#endif  // FINECAP_REFINE_PROBLEM_SIZE_H_
