#include "finecap/refine/problem_size.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <glog/logging.h>

#include "finecap/energy/frame_energy.h"
#include "finecap/energy/similarity_needs.h"
#include "finecap/model/gaussian_pairs.h"
#include "finecap/util/error.h"
#include "refine/surface_sampling.h"

namespace finecap {
namespace {

// At most this many surface Gaussians per camera have their pairs counted, evenly spread: enough
// for a count within a few per cent (synth_skirt: 3.2 M pairs counted within 1 %), in a tenth of
// the time of counting them all, which the forecast once did on every camera of the first frame.
constexpr int kSampledSurfaceGaussians = 1000;

// The peak resident memory of a run without the detail stage (below), fitted (least squares,
// non-negative) to 18 refinements on 2 cores (bench/memory_forecast.sh and the same runs by hand:
// synth_demo with 512 and 128 pixel cameras and with two subdivision levels, synth_skirt with 8
// and 4 cameras, a wider k_max and a smaller sigma_hat, the surface_color similarity, the
// Middlebury temple with and without held-out cameras and with a smaller k_max; one frame and
// three; 42 to 289 MB): all
// within 0.86-1.19 of their measured peaks, and within 0.84-1.16 when each is left out of the fit
// (the default similarity; the surface_color similarity, three runs, 0.72-1.27).
constexpr double kBaseMegabytes = 29.0;  // The process: code, libraries, thread stacks, allocator.
// The 8-bit images of the frame read and the buffers of decoding them.
constexpr double kBytesPerPixel = 4.2;
// A camera with lens distortion: its undistortion maps, kept for the run (OpenCV's fixed-point
// maps, 4 + 2 bytes a pixel; synth_noisy, which has distortion, peaked 46 MB above the forecast
// without them, 5.7 bytes a pixel of its 8 cameras).
constexpr double kBytesPerUndistortedPixel = 6.0;
// Per frame held at once (the one solved and those prepared ahead): the pairs, while they are
// built (the consensus energy keeps none once its colour tables are made), and the consensus
// similarity's patch rows per surface Gaussian and camera that sees it; its colour tables are
// counted exactly (24 B per node).
constexpr double kBytesPerConsensusPair = 6.0;
constexpr double kBytesPerPair = 7.4;
constexpr double kTabledBytesPerObservation = 40.0;
// Residual blocks, neighbourhoods, the regulariser, the sweep's costs and the solver's sparse
// matrices, which grow with the surface Gaussians (not with the cameras that see them): with
// conjugate gradients (Ceres' CGNR, the default), and what the sparse Cholesky factorisation's
// normal equations and factor add.
constexpr double kBytesPerSurfaceGaussian = 1100.0;
constexpr double kBytesPerSurfaceGaussianCholesky = 400.0;  // synth_skirt: 104 against 100 MB.
// Without the detail stage a run of several frames prepares up to two ahead while one is solved
// (sequence.cc), and holds three frames' worth at its peak even with two frames to run
// (synth_skirt: 166 MB for two frames, 173 MB for three).
constexpr int kFramesHeldBySeveral = 3;

// Seconds of one frame without the detail stage: the pairs dominate large problems (the colour
// tables and pair lists run over them), the solver's work per Gaussian small ones. Refitted to the
// first frames of bench/memory_forecast.sh's three captures (synth_demo 0.2 s, synth_skirt 0.5 s,
// the temple 2.9 s on the idle machine): within a factor of 2 of each.
constexpr double kSecondsPerPair = 0.16e-6;
constexpr double kSecondsPerSurfaceGaussian = 0.02e-3;

// With the detail stage (ConsensusOptions::sample_spacing, the default) a frame's memory has two
// peaks, not one sum: the surface Gaussians' stage (the images read, the pairs while they are
// built, the colour tables) and the detail stage (the images as floats, blurred, the surface
// samples, the table of the reads' rays). The first stage's energy is freed before the detail
// stage is built, but the allocator keeps its pages, which the detail stage then reuses: the
// resident memory after the first stage never falls (watched through /proc/self/status on the
// temple and Sceaux), and the peak is the larger of the two. A run of several frames also holds
// the frame read and prepared ahead (one, as the detail stage reads its frame's images after the
// preparation: sequence.cc), its images and its colour tables, its pairs freed once the tables
// are made.
//
// Fitted 2026-12-06 (a grid minimising the worst log ratio, the process's 29 MB and the colour
// tables, an exact count, held fixed) to the first frames of seven runs on 2 cores, each at the
// search range it ended with: synth_demo (4 cameras of 512 px, its faces split 8 a side then),
// synth_skirt (8 cameras of 1004 px), the Middlebury temple (16 cameras, and 12 with
// configs/temple.yaml, at the 16.6 mm its sweep widened to), Sceaux (10 cameras of 708 x 532, and
// 8 with its heldout.yaml) and Sceaux at full resolution (8 of 2832 x 2128, 16 a side then; too
// many reads to keep their table): every run's peak within 0.93-1.08 of its forecast, and the first
// stage's own peak, measured apart, within 0.93-1.08 of its part. A two-frame synth_skirt run came
// to 0.98 of its forecast. The constants' sizes are those of what they count: 4.5 bytes a pixel for
// the 8-bit images and their decoding, 6.5 a pair (the pair lists' 8 bytes, most of them held at
// once), 18.5 a pixel for the detail stage's images (3 floats, the blur's buffer, the 8-bit images
// still held) and 270 a sample (position, normal, blend weights, visibility flags per camera, the
// patches' member lists).
constexpr double kBytesPerPixelWithSamples = 4.5;
constexpr double kBytesPerConsensusPairWithSamples = 6.5;
constexpr double kBytesPerSampledPixel = 18.5;
constexpr double kBytesPerSurfaceSample = 270.0;
// The refined mesh's term (ConsensusOptions::surface_weight > 0), per surface sample: its blocks'
// members' corners and blend weights, and its rows. Measured as the difference it makes to the
// peak: synth_skirt 50, Sceaux (8 cameras) 70, Sceaux at full resolution 46 bytes a sample.
constexpr double kBytesPerSurfaceSampleOfTheMeshTerm = 50.0;
// Time, fitted 2026-12-04 to 9 runs (the captures above, two frames of synth_skirt and the soak's
// capture), measured as the frame's CPU seconds over 2 cores (the machine was shared, wall clocks
// 2 to 4 times that), minimax on the log ratio: all 9 within 0.59-1.69. Per pair (the colour tables
// are built over them), and per sample read in a patch in one camera over the evaluations of the
// detail stage's two passes. The spread is real: a read in a full-resolution image (72 MB of
// floats a camera) misses the caches that the 708 x 532 images fit in, and Sceaux at full
// resolution, 135 M reads an evaluation against 7 M, takes 1.7 times its forecast while Sceaux
// takes 0.6 times it; a model of the caches is left to do. On the wall clock of the idle machine
// (2026-12-05, the held-out score included) all five captures of bench/memory_forecast.sh took
// 0.57 to 1.0 times their forecast.
constexpr double kSecondsPerPairWithSamples = 0.355e-6;
constexpr double kSecondsPerSampleRead = 0.116e-6;

// The held-out score, per pixel of a held-out view and training view warped into it (for the
// three surfaces refine scores): Sceaux's two held-out views with 4 training views each took
// 0.40 s at the capture's 708 x 532 and 6.1 s at full resolution (2832 x 2128) on 2 idle cores,
// 0.134 and 0.127 us a pixel pair.
constexpr double kSecondsPerHeldOutPixelPair = 0.13e-6;

// The samples of a regular vertex's patch of `rings` rings, its faces split into `segments` a side:
// the hexagon of radius rings * segments without its rim.
int SamplesPerRegularPatch(int rings, int segments) {
  const int radius = rings * segments;
  return 1 + 3 * (radius - 1) * radius;
}

// The pairs that `energy`'s similarity, searching within `k_max`, makes of `surface` and the
// cameras' image Gaussians `images`, where `visible` says a camera sees a vertex: a sample of at
// most kSampledSurfaceGaussians per camera, scaled.
double CountPairs(const std::vector<Camera>& cameras, const std::vector<ImageGaussians>& images,
                  const SurfaceGaussians& surface,
                  const std::vector<std::vector<unsigned char>>& visible,
                  const EnergyOptions& energy, double k_max) {
  PairOptions pair_options = EnergyPairOptions(energy);
  pair_options.k_max = k_max;
  double pairs = 0.0;
  for (size_t c = 0; c < cameras.size(); ++c) {
    std::vector<unsigned char> seen;
    for (int v : surface.vertex_ids) seen.push_back(visible[c][v]);
    const long observations = std::count(seen.begin(), seen.end(), 1);
    const int stride = static_cast<int>(std::max<long>(
        1, (observations + kSampledSurfaceGaussians - 1) / kSampledSurfaceGaussians));
    pairs += CountCameraPairs(cameras[c], images[c], surface, seen, pair_options, stride);
  }
  return pairs;
}

// The bytes of a frame that grow with its search range `k_max`: its `num_pairs` while they are
// built and, for the consensus similarity, its colour tables over the range.
struct RangeBytes {
  double pairs = 0.0;
  double tables = 0.0;
};

RangeBytes RangeBytesOf(double num_pairs, long num_observations, EnergyOptions energy, double k_max,
                        double sigma_hat) {
  const SimilarityNeeds needs = NeedsOf(energy);
  RangeBytes bytes;
  bytes.pairs = num_pairs * (needs.reads_surface_samples ? kBytesPerConsensusPairWithSamples
                             : needs.compares_patches    ? kBytesPerConsensusPair
                                                         : kBytesPerPair);
  energy.k_max = k_max;
  if (const int nodes = ColorTableNodes(energy, sigma_hat); nodes > 0) {
    // Its colour tables: value and derivative, 3 floats each, per node.
    bytes.tables = num_observations * (nodes * 24.0 + kTabledBytesPerObservation);
  }
  return bytes;
}

// The samples the detail stage of a frame of `size` reads in one evaluation: each patch's in each
// camera that sees it.
double SampleReads(const ProblemSize& size) {
  return size.num_observations * double(size.samples_per_patch);
}

// The bytes of the detail stage of a frame of `size` (its pixels, samples and observations set):
// the images as floats, the samples, the reads' table where it is kept and, with
// `mesh_term`, the refined mesh's term.
double DetailStageBytes(const ProblemSize& size, bool mesh_term) {
  return size.num_pixels * kBytesPerSampledPixel +
         size.num_surface_samples *
             (kBytesPerSurfaceSample + (mesh_term ? kBytesPerSurfaceSampleOfTheMeshTerm : 0.0)) +
         SampleRayTableBytes(SampleReads(size));
}

// The peak bytes, beyond the process's own and the undistortion maps, of a run of `num_frames`
// frames of `size` whose range takes `range`, with a detail stage of `detail_bytes` when it has
// one (`sampled`).
double FramesBytes(const ProblemSize& size, const RangeBytes& range, bool sampled,
                   double detail_bytes, int num_frames) {
  if (!sampled) {
    const int frames_held = num_frames > 1 ? kFramesHeldBySeveral : 1;
    return size.num_pixels * kBytesPerPixel + frames_held * (range.pairs + range.tables) +
           size.num_surface_gaussians * kBytesPerSurfaceGaussian;
  }
  const double images = size.num_pixels * kBytesPerPixelWithSamples;
  const double first_stage = images + range.pairs + range.tables;
  const double frame_ahead = num_frames > 1 ? images + range.tables : 0.0;
  return frame_ahead + std::max(first_stage, detail_bytes);
}

}  // namespace

ProblemSize EstimateProblemSize(const SequenceModel& model, const ReferenceColors& colors,
                                const FrameInput& frame, const RefineOptions& options,
                                int num_frames, double undistorted_pixels) {
  ProblemSize size;
  const Mesh fine = model.Subdivide(frame.coarse);
  const Eigen::Matrix3Xd normals = ComputeVertexNormals(fine);
  const auto visible = ComputeFrameVisibility(fine, normals, frame.cameras, options.visibility,
                                              FallbackCamerasWanted(options), frame.masks);
  size.num_fine_vertices = fine.num_vertices();
  size.num_refined_vertices = static_cast<int>(model.refined_vertices().size());
  const std::vector<float> view_confidence = ViewConfidence(
      frame.cameras, fine.vertices, normals, CamerasWanted(options), options.visibility, visible);
  for (int v : model.refined_vertices()) {
    bool seen = false;
    for (const auto& camera : visible) seen = seen || camera[v];
    size.num_unseen_refined_vertices += seen ? 0 : 1;
    size.num_well_seen_refined_vertices += view_confidence[v] >= kConfidentAt ? 1 : 0;
  }
  for (const auto& camera : visible) {
    size.visible_per_camera.push_back(
        static_cast<int>(std::count(camera.begin(), camera.end(), 1)));
  }

  const std::vector<ImageGaussians> images = FrameImageModels(frame, options.image);
  const SurfaceGaussians surface =
      MakeSurfaceGaussians(fine.vertices, normals, model.refined_vertices(), colors);
  size.num_surface_gaussians = surface.size();
  for (size_t c = 0; c < frame.cameras.size(); ++c) {
    size.num_observations += std::count_if(surface.vertex_ids.begin(), surface.vertex_ids.end(),
                                           [&](int v) { return visible[c][v] != 0; });
    size.num_image_gaussians += images[c].size();
    size.num_pixels += double(frame.cameras[c].width) * frame.cameras[c].height;
  }
  const auto pairs_within = [&](double k_max) {
    return CountPairs(frame.cameras, images, surface, visible, options.energy, k_max);
  };
  size.num_pairs = pairs_within(options.energy.k_max);
  const RangeBytes range = RangeBytesOf(size.num_pairs, size.num_observations, options.energy,
                                        options.energy.k_max, options.sigma_hat);
  const bool sampled = NeedsOf(options.energy).reads_surface_samples;
  double detail_bytes = 0.0, detail_seconds = 0.0;
  if (sampled) {
    const int segments =
        SampleSegments(fine, frame.cameras, options.energy.consensus.sample_spacing);
    // segments^2 samples a vertex: V vertices, 3 V edges and 2 V faces on a closed mesh.
    size.num_surface_samples = fine.num_vertices() * double(segments) * segments;
    size.samples_per_patch = SamplesPerRegularPatch(PatchRingsAt(options), segments);
    detail_bytes = DetailStageBytes(size, options.energy.consensus.surface_weight > 0.0);
    detail_seconds = SampleReads(size) * kSecondsPerSampleRead;
  }
  const bool cholesky = options.solver.type == SolverType::kCeres &&
                        options.solver.linear_solver != LinearSolverType::kCgnr;
  const double run_bytes =
      undistorted_pixels * kBytesPerUndistortedPixel +
      (cholesky ? size.num_surface_gaussians * kBytesPerSurfaceGaussianCholesky : 0.0);
  const auto peak_mb = [&](const RangeBytes& frame_range) {
    return kBaseMegabytes +
           (run_bytes + FramesBytes(size, frame_range, sampled, detail_bytes, num_frames)) / 1e6;
  };
  size.peak_memory_mb = peak_mb(range);
  size.widest_k_max = WidestSearchRange(options);
  size.widest_peak_memory_mb = size.peak_memory_mb;
  if (size.widest_k_max > options.energy.k_max) {
    size.widest_peak_memory_mb =
        peak_mb(RangeBytesOf(pairs_within(size.widest_k_max), size.num_observations, options.energy,
                             size.widest_k_max, options.sigma_hat));
  }
  size.seconds_per_frame = sampled ? size.num_pairs * kSecondsPerPairWithSamples + detail_seconds
                                   : size.num_pairs * kSecondsPerPair +
                                         size.num_surface_gaussians * kSecondsPerSurfaceGaussian;
  // What a refit of the constants needs beside each run's measured peak and time.
  VLOG(1) << "memory forecast of " << num_frames << " frame(s): " << size.num_pixels << " pixels, "
          << undistorted_pixels << " undistorted, " << size.num_pairs << " pairs, "
          << size.num_observations << " observations of " << size.num_surface_gaussians
          << " surface Gaussians, " << size.num_surface_samples << " surface samples, "
          << size.samples_per_patch << " samples a patch; pairs " << range.pairs / 1e6
          << " MB, colour tables " << range.tables / 1e6 << " MB, detail stage "
          << detail_bytes / 1e6 << " MB, " << (cholesky ? "Cholesky" : "CGNR");
  return size;
}

void AddHeldOutScoring(const std::vector<CalibratedImage>& held_out, int num_training,
                       int neighbours, ProblemSize* size) {
  double pixel_pairs = 0.0;
  for (const CalibratedImage& view : held_out) {
    pixel_pairs +=
        double(view.camera.width) * view.camera.height * std::min(neighbours, num_training);
  }
  size->seconds_per_frame += pixel_pairs * kSecondsPerHeldOutPixelPair;
}

void RequireMemoryFor(const ProblemSize& size, int num_frames, const RefineOptions& options,
                      int max_memory_mb, const AvailableMemory& available) {
  const double limit = MemoryLimitMb(max_memory_mb, available);
  if (!(size.peak_memory_mb > limit)) return;
  const bool own_limit = limit < available.megabytes;
  std::ostringstream problem;
  problem.precision(2);
  problem << std::fixed << "the forecast peak memory of this run, "
          << std::lround(size.peak_memory_mb) << " MB, exceeds the " << std::lround(limit) << " MB "
          << (own_limit ? "it is allowed" : "available to it")
          << "; lower RefineOptions::subdivision_levels (now " << options.subdivision_levels
          << ", each level about 4 times the surface), the size of the images ("
          << size.num_pixels / 1e6 << " Mpixel a frame over " << size.visible_per_camera.size()
          << " cameras)";
  if (num_frames > 1) {
    problem << " or the frames held at once (a run of several frames prepares the next ones "
               "while one is solved; one frame a run, --frames I:I+1, holds one)";
  }
  problem << (own_limit ? ", or raise SequenceOptions::max_memory_mb" : ", or free memory for it");
  throw Error(own_limit ? "SequenceOptions::max_memory_mb" : available.source, problem.str());
}

double MemoryLimitMb(int max_memory_mb, const AvailableMemory& available) {
  const bool own_limit = max_memory_mb > 0 && max_memory_mb < available.megabytes;
  return own_limit ? max_memory_mb : available.megabytes;
}

double UndistortedPixels(const Capture& capture) {
  double pixels = 0.0;
  for (const Camera& camera : capture.rig()) {
    if (camera.HasDistortion()) pixels += double(camera.width) * camera.height;
  }
  return pixels;
}

}  // namespace finecap
