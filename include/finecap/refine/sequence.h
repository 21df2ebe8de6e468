// A sequence refined frame after frame into a run folder (run_folder.h): the library's frame loop.
//
// RefineSequence owns what a run over many frames needs beyond RefineFrame (refine.h): the
// reference colours, computed once from the reference frame, saved with the recipe they were made
// with and checked on every reuse; resume (a done frame is skipped, so a killed run, a second shard
// or the same command again finishes the sequence); warm start (each frame seeded from the previous
// frame's saved displacement, as solved: see SolvedDisplacement); the next frame read on a thread
// of its own while this one is solved; the held-out cameras' score, with keep_input_if_worse; and
// the errors against the capture's ground truth when it has any. It writes nothing but the run
// folder's files and prints nothing: what a user should see is reported to a SequenceObserver.
#ifndef FINECAP_REFINE_SEQUENCE_H_
#define FINECAP_REFINE_SEQUENCE_H_

#include <string>
#include <vector>

#include <Eigen/Core>

#include "finecap/io/capture.h"
#include "finecap/io/frame_range.h"
#include "finecap/io/mesh_io.h"
#include "finecap/measure/heldout_score.h"
#include "finecap/refine/frame_reader.h"
#include "finecap/refine/frame_stats.h"
#include "finecap/refine/problem_size.h"
#include "finecap/refine/refine.h"
#include "finecap/refine/run_folder.h"
#include "finecap/util/enum_names.h"
#include "finecap/util/option_fields.h"

namespace finecap {

// Where the reference frame colours the surface Gaussians.
enum class ReferenceSurface {
  kCoarse,   // At the reference frame's input (coarse) surface, as the paper did.
  kRefined,  // At the reference frame refined first by a similarity that needs no colours.
};
const std::vector<EnumName<ReferenceSurface>>& EnumNames(ReferenceSurface);

// How the colours that surface_color and paper compare with the images are taken and kept over a
// sequence. The consensus similarity uses no such colours, and under it these options do nothing
// (the colours are then taken at the coarse surface, for the figures that need some). The fields
// are documented where Fields() declares them (docs/configuration.md: model); the comments below
// add what the documentation does not say.
struct ReferenceColorOptions {
  // kRefined refines the reference frame with finecap's defaults for everything that a
  // similarity tunes (ReferencePassOptions): at a coarse surface the colours belong to the wrong
  // surface points wherever the surface has detail the input lacks.
  ReferenceSurface reference_surface = ReferenceSurface::kRefined;
  // Rate r: every colour a refined frame's surface shows (where a camera saw the vertex) is
  // blended in, eta <- eta + r (eta_frame - eta). Frame t uses the colours that frame t - 1 left,
  // saved in the run folder (so a resumed run continues exactly), and a frame whose predecessor
  // is not done there is refused.
  double follow_colors = 0.0;
  // Anchor a: eta <- eta + a (eta_reference - eta) after each update. A steady change of the
  // images is followed to the share r (1 - a) / (r + a - r a) of it.
  double follow_anchor = 0.1;

  bool following() const { return follow_colors > 0.0; }
  static const OptionFields<ReferenceColorOptions>& Fields();  // option_fields.h
  void Check() const;
};

struct SequenceOptions {
  // How each frame is refined. Its lengths should be resolved from the scene first
  // (ResolveSceneScaleDefaults, scene_scale.h).
  RefineOptions refine;
  // The frame whose images colour the surface Gaussians of every frame. Its documentation and
  // max_memory_mb's are where Fields() declares them (docs/configuration.md: model.reference_frame,
  // runtime.max_memory_mb).
  int reference_frame = 0;
  // How the colours are taken and kept over the sequence.
  ReferenceColorOptions colors;
  // Cameras that refinement never sees (not even for the reference colours): each frame's result
  // and input are scored in them, and with refine.keep_input_if_worse a result that scores worse
  // than its input is replaced by the input. Default none.
  std::vector<std::string> held_out_cameras;
  HeldOutOptions held_out_score;
  // Refine a frame without a camera whose image cannot be read (reported to the observer) instead
  // of failing. Default false.
  bool skip_unreadable_cameras = false;
  // How the refined meshes are written. Default PLY.
  MeshFormat mesh_format = MeshFormat::kPly;
  // The forecast is EstimateProblemSize's, the memory available ReadAvailableMemory's. A run is
  // refused before it reads more than its first frame or writes anything.
  int max_memory_mb = 0;

  static const OptionFields<SequenceOptions>& Fields();  // option_fields.h
  void Check() const;
};

// Everything the reference colours depend on (ComputeSequenceColors, and the held-out cameras it
// must not see), as one line of `name=value` fields: two runs whose recipes are equal may share
// one file of reference colours.
std::string ReferenceColorRecipe(const SequenceOptions& options);

// The options with which the reference frame is refined before it colours the surface (with
// ReferenceSurface::kRefined): finecap's defaults (the consensus similarity, which needs no
// colours), their lengths resolved for `capture`'s scene, with the configured subdivision and
// regulariser neighbourhood (the sequence's model is built with those) and threads. Not the
// configured similarity's own settings: those of surface_color (a 35 degree view cap, no sweep,
// chromaticity) leave most patches with fewer than the two cameras consensus needs.
RefineOptions ReferencePassOptions(const RefineOptions& configured, const Capture& capture,
                                   int reference_frame);

// The solver options of a frame solved while the frames after it are prepared beside it: Ceres'
// own loops (its pass over the residual blocks and its linear algebra) on one thread fewer than
// `configured` gives them (0: all cores), and at least one. The frame ahead's preparation keeps
// a core busy all the while, and Ceres 2.1 deals its blocks to its threads in turn: on
// synth_skirt, two cores, its loops on one thread took a frame from 0.264 to 0.255 s (30 frames,
// five alternating runs, medians, every run faster). The similarity's shared work keeps every
// thread.
SolverOptions SolverOptionsBesideWorkAhead(const SolverOptions& configured);

// What the followed colours saved after a frame depend on: ReferenceColorRecipe and the two
// follow options.
std::string FollowedColorRecipe(const SequenceOptions& options);

// `previous` (the colours frame t used) updated by frame t's own colours `frame` (taken at its
// refined surface) and pulled towards `reference`, as ReferenceColorOptions says; only where
// `reference` is valid. Returns `previous` pulled towards the reference only, where `frame` has
// no valid colour.
ReferenceColors FollowColors(const ReferenceColors& previous, const ReferenceColors& frame,
                             const ReferenceColors& reference,
                             const ReferenceColorOptions& options);

// The reference colours saved at `path`, or, when there is no such file, those of the reference
// frame (at its coarse or refined surface, options.colors.reference_surface), computed, saved
// there with their recipe and read back (so that a run uses exactly what a
// later resumed run or shard reads). A saved file made with another recipe throws Error naming
// `path` and the fields that differ (a file saved before recipes were is checked on its colour
// space, sigma_hat and method). Cameras skipped in the reference frame go to *skipped (may be
// null).
ReferenceColors LoadOrComputeReferenceColors(const SequenceModel& model,
                                             const SequenceOptions& options, Capture* capture,
                                             const std::string& path,
                                             std::vector<SkippedCamera>* skipped = nullptr);

// The reference colours of `reference` (the reference frame, read, without its held-out cameras),
// computed, saved at `path` with their recipe and read back, as LoadOrComputeReferenceColors does
// when there is no file.
ReferenceColors SaveReferenceColors(const SequenceModel& model, const SequenceOptions& options,
                                    Capture* capture, const FrameInput& reference,
                                    const std::string& path);

// The FineGroundTruth (refine.h) of `frame`, whose coarse mesh is `coarse`: empty when the capture
// has no true surface for it.
FineGroundTruth TrueFineGroundTruth(const Capture& capture, const SequenceModel& model,
                                    const Mesh& coarse, int frame);

// Where a done frame's solve ended, per fine vertex (SolvedDisplacement of its saved
// displacement, kept_input read from its record): what seeds the next frame with warm start.
Eigen::VectorXd ReadSolvedDisplacement(const FrameFiles& files, int num_fine_vertices,
                                       const RefineOptions& options);

// What RefineSequence tells its caller while it runs; every method does nothing unless
// overridden. Called on the caller's thread.
class SequenceObserver {
 public:
  virtual ~SequenceObserver() = default;
  // Temporaries that a killed run left in the run folder were removed, before anything else.
  virtual void StaleFilesRemoved(int /*count*/) {}
  // Before the first frame: the frames to run (done ones included), the first frame's input as
  // refinement sees it and the size of its problem.
  virtual void Starting(int /*num_frames*/, const FrameInput& /*first*/,
                        const ProblemSize& /*size*/) {}
  // Right after Starting: a frame whose sweep widened its search range to the widest it may
  // (ProblemSize::widest_k_max) would need more memory than the run may take, `limit_mb`.
  virtual void WidestRangeMayNotFit(const ProblemSize& /*size*/, double /*limit_mb*/) {}
  // A camera's image of `frame` could not be read and the frame goes on without it
  // (skip_unreadable_cameras).
  virtual void CameraSkipped(const std::string& /*frame*/, const SkippedCamera& /*camera*/) {}
  // No camera sees any vertex to refine in `frame`: its input surface is written.
  virtual void NothingToRefine(const std::string& /*frame*/) {}
  // A frame was found done in the run folder and skipped.
  virtual void FrameAlreadyDone(const std::string& /*frame*/) {}
  // A frame was refined and its files written; `stats` is its record.
  virtual void FrameRefined(const FrameStats& /*stats*/) {}
};

struct SequenceResult {
  int refined = 0;       // Frames refined by this call.
  int already_done = 0;  // Frames found done and skipped.
  // Over the frames refined now that have ground truth (`measured` of them): the root mean square
  // of their per-frame RMS errors (textured region) of the coarse mesh as given, of its
  // subdivision and of the result, millimetres (FrameStats); NaN when none.
  int measured = 0;
  double rms_coarse_mm = 0.0;
  double rms_subdivided_mm = 0.0;
  double rms_refined_mm = 0.0;
  // Over the frames refined now that have a flicker figure (`flickered` of them): the root mean
  // square of their flicker_*_mm (FrameStats); NaN when none.
  int flickered = 0;
  double flicker_coarse_mm = 0.0;
  double flicker_subdivided_mm = 0.0;
  double flicker_refined_mm = 0.0;
  // The mean over the frames refined now of their share of vertices refined with confidence
  // (FrameStats::confident_share); NaN when none was.
  double confident_share = 0.0;
};

// Refines frames [frames.begin, frames.end) of `capture` into the run folder `out` (created with
// its subfolders when missing); frames already done there are skipped. The topology and the
// refined vertices are those of frame 0. Several processes may run on one folder at once with
// disjoint frames (shards). Throws Error (options.Check(), unreadable input, a reference colour
// file of another recipe) before a frame's files are written, never leaving one half-written; a
// run whose memory forecast exceeds what it may use (SequenceOptions::max_memory_mb,
// RequireMemoryFor) throws before it creates or writes anything in `out`. `observer` may be null.
SequenceResult RefineSequence(Capture* capture, const FrameRange& frames,
                              const SequenceOptions& options, const std::string& out,
                              SequenceObserver* observer = nullptr);

}  // namespace finecap

#endif  // FINECAP_REFINE_SEQUENCE_H_
