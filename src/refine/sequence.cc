#include "finecap/refine/sequence.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "finecap/energy/similarity_needs.h"
#include "finecap/measure/metrics.h"
#include "finecap/solvers/solver_trace.h"
#include "finecap/util/atomic_file.h"
#include "finecap/util/error.h"
#include "finecap/util/memory.h"
#include "measure/ground_truth.h"
#include "refine/scene_scale.h"

namespace finecap {
namespace {

namespace fs = std::filesystem;

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// The `name=value` fields of a recipe line.
std::vector<std::string> RecipeFields(const std::string& recipe) {
  std::istringstream words(recipe);
  std::vector<std::string> fields;
  for (std::string field; words >> field;) fields.push_back(field);
  return fields;
}

// The fields of `saved` that `wanted` has otherwise, "a=1 (asked: a=2), ...".
std::string RecipeDifference(const std::string& saved, const std::string& wanted) {
  const std::vector<std::string> old_fields = RecipeFields(saved),
                                 new_fields = RecipeFields(wanted);
  std::string text;
  for (size_t i = 0; i < std::max(old_fields.size(), new_fields.size()); ++i) {
    const std::string was = i < old_fields.size() ? old_fields[i] : "(none)";
    const std::string asked = i < new_fields.size() ? new_fields[i] : "(none)";
    if (was != asked) text += (text.empty() ? "" : ", ") + was + " (asked: " + asked + ")";
  }
  return text;
}

// A saved file of reference colours fits `options`: by its recipe, or, for a file saved before
// recipes were, by the three fields it holds.
void RequireSameRecipe(const ReferenceColors& saved, const SequenceOptions& options,
                       const std::string& path) {
  if (!saved.recipe.empty()) {
    const std::string wanted = ReferenceColorRecipe(options);
    Require(
        saved.recipe == wanted, path,
        "was made with " + RecipeDifference(saved.recipe, wanted) + ": use another output folder");
    return;
  }
  const RefineOptions& refine = options.refine;
  // The file holds sigma_hat to 9 significant digits, which a length chosen from the scene needs
  // all of.
  Require(saved.color_space == refine.image.color_space &&
              std::abs(saved.sigma_hat - refine.sigma_hat) <= 1e-8 * refine.sigma_hat &&
              saved.method == refine.reference_colors,
          path,
          "was made with colour space " + ColorSpaceName(saved.color_space) + ", sigma_hat " +
              std::to_string(saved.sigma_hat) + " and method " + EnumToString(saved.method) +
              ", but the config asks for " + ColorSpaceName(refine.image.color_space) + ", " +
              std::to_string(refine.sigma_hat) + " and " + EnumToString(refine.reference_colors) +
              ": use another output folder");
}

// Whether the colours are taken at the refined reference surface: only when the similarity
// compares colours, since consensus would refine the reference frame for nothing.
bool TakesColorsAtRefinedSurface(const SequenceOptions& options) {
  return options.colors.reference_surface == ReferenceSurface::kRefined &&
         !NeedsOf(options.refine.energy).colors_of_each_frame;
}

// Whether each frame's colours follow the ones before (pointless under consensus).
bool FollowsColors(const SequenceOptions& options) {
  return options.colors.following() && !NeedsOf(options.refine.energy).colors_of_each_frame;
}

// The reference frame's colours, at its coarse or first refined surface.
ReferenceColors ComputeReferenceFrameColors(const SequenceModel& model,
                                            const SequenceOptions& options, Capture* capture,
                                            const FrameInput& reference) {
  if (!TakesColorsAtRefinedSurface(options)) {
    return ComputeSequenceColors(model, reference, options.refine);
  }
  const RefineOptions pass =
      ReferencePassOptions(options.refine, *capture, options.reference_frame);
  // The consensus similarity takes its colours from the frame itself: none are passed in.
  const FrameResult refined = RefineFrame(model, ReferenceColors{}, reference, pass);
  return ComputeSurfaceColors(refined.refined, reference, options.refine);
}

// The refined vertices outside and inside the capture's textureless region.
struct Regions {
  std::vector<int> textured, textureless;
};

Regions SplitByTexture(const SequenceModel& model, const Capture& capture) {
  std::vector<bool> textureless(model.num_fine_vertices(), false);
  for (int v : model.SubdivideIds(capture.textureless_vertices())) textureless[v] = true;
  Regions regions;
  for (int v : model.refined_vertices()) {
    (textureless[v] ? regions.textureless : regions.textured).push_back(v);
  }
  return regions;
}

// The errors of the coarse mesh as given, of its subdivision and of the result against `truth`
// (the frame's TrueFineGroundTruth; empty: none), into `stats`.
void AddGroundTruthErrors(const FineGroundTruth& truth, const Regions& regions,
                          const FrameResult& result, FrameStats* stats) {
  if (truth.empty()) return;
  // Only where the result has a displacement: every figure over the same vertices.
  const Eigen::VectorXd zero = result.k.array().isFinite().select(0.0 * result.k, result.k);
  const auto rms_mm = [](const Eigen::VectorXd& estimate, const Eigen::VectorXd& truth,
                         const std::vector<int>& region) {
    return 1000.0 * ComputeErrorStats(estimate, truth, region).rms;
  };
  stats->rms_coarse_mm = rms_mm(zero, truth.coarse_error, regions.textured);
  stats->rms_subdivided_mm = rms_mm(zero, truth.k_true, regions.textured);
  stats->rms_refined_mm = rms_mm(result.k, truth.k_true, regions.textured);
  stats->rms_textureless_coarse_mm = rms_mm(zero, truth.coarse_error, regions.textureless);
  stats->rms_textureless_subdivided_mm = rms_mm(zero, truth.k_true, regions.textureless);
  stats->rms_textureless_refined_mm = rms_mm(result.k, truth.k_true, regions.textureless);
}

// The flicker of the three surfaces between `before` and `now` (a frame's SignedErrors and the
// frame before's; empty: unknown) over the textured region, into `stats`.
void AddFlicker(const SignedErrors& before, const SignedErrors& now, const Regions& regions,
                FrameStats* stats) {
  const FlickerStats flicker = ComputeFlickers(before, now, regions.textured);
  stats->flicker_coarse_mm = 1000.0 * flicker.coarse.rms;
  stats->flicker_subdivided_mm = 1000.0 * flicker.subdivided.rms;
  stats->flicker_refined_mm = 1000.0 * flicker.refined.rms;
}

// A frame's signed errors against its truth (empty: no truth), and which frame they are of.
struct FrameErrors {
  int frame = -1;
  SignedErrors errors;
};

SignedErrors SignedErrorsAgainst(const FineGroundTruth& truth, const Eigen::VectorXd& k) {
  if (truth.empty()) return {};
  return SignedErrorsOf(k, truth.k_true, truth.coarse_error);
}

// The held-out score of the frame's coarse mesh as given, of its subdivision and of its result
// (as solved), into `stats`; a result whose held-out NCC is below the input's as given is
// flagged worse and, with keep_input_if_worse, replaced by the subdivided input.
void ScoreInHeldOutViews(const SequenceOptions& options, const SequenceModel& model,
                         const FrameInput& input, const std::vector<CalibratedImage>& held_out,
                         FrameResult* result, FrameStats* stats) {
  if (held_out.empty()) return;
  const auto start = std::chrono::steady_clock::now();
  const Mesh fine_input = model.Subdivide(input.coarse);
  const HeldOutScore score =
      ScoreHeldOutViews(CalibratedImagesOf(input), held_out,
                        {&input.coarse, &fine_input, &result->refined}, options.held_out_score);
  stats->heldout_ncc_input = score.mean[0].ncc;
  stats->heldout_ncc_subdivided = score.mean[1].ncc;
  stats->heldout_ncc_refined = score.mean[2].ncc;
  stats->heldout_mad_input = score.mean[0].mad;
  stats->heldout_mad_subdivided = score.mean[1].mad;
  stats->heldout_mad_refined = score.mean[2].mad;
  stats->seconds_heldout = SecondsSince(start);
  if (!(score.mean[2].ncc < score.mean[0].ncc)) return;
  result->worse = stats->worse = true;
  if (options.refine.keep_input_if_worse && !result->kept_input) {
    KeepInputSurface(fine_input, result);
    stats->kept_input = true;
  }
}

// The solved displacement of the frame before `frame`, which seeds `frame` with
// refine.warm_start and reaches the terms that read it (SimilarityNeeds::reads_frame_before); empty
// when that frame is not done in `out` (the frame then starts as a first frame). Always from the
// saved files, so that a resumed run or a shard starts its first frame exactly as a run that never
// stopped starts every frame.
Eigen::VectorXd SolvedFrameBefore(const std::string& out, const Capture& capture, int frame,
                                  const SequenceOptions& options, const SequenceModel& model) {
  if (frame == 0) return {};
  const FrameFiles previous = FrameFilesIn(out, capture.frame_name(frame - 1), options.mesh_format);
  if (!FrameDone(previous)) return {};
  return ReadSolvedDisplacement(previous, model.num_fine_vertices(), options.refine);
}

// Writes the frame's files, its record last (it marks the frame done).
void WriteFrame(const FrameFiles& files, const FrameResult& result, MeshFormat format,
                FrameStats* stats, std::chrono::steady_clock::time_point start,
                double cpu_seconds_at_start, const StatsLog& log) {
  const Eigen::VectorXd quality = result.k.array().isFinite().select(result.k, 0.0);
  WriteMesh(files.mesh, result.refined, {result.normals, {}, quality}, format);
  WriteDisplacement(files.displacement, result.k);
  WriteConfidence(files.confidence, result.confidence);
  WriteTextFileAtomically(files.trace, SolverTraceCsv(result.summary.trace));
  // Inside the frame's time, so that the CPU is never more than that time on every core.
  stats->cpu_seconds = ProcessCpuSeconds() - cpu_seconds_at_start;
  stats->seconds = SecondsSince(start);
  const std::string record = ToJson(*stats);
  WriteTextFileAtomically(files.stats, record + "\n");
  log.Append(record);
}

// The root mean square over frames of a figure of the three surfaces (the input as given, its
// subdivision, the result), each frame's own RMS squared and summed.
class RmsOverFrames {
 public:
  void Add(double coarse, double subdivided, double refined) {
    coarse2_ += coarse * coarse;
    subdivided2_ += subdivided * subdivided;
    refined2_ += refined * refined;
    ++frames_;
  }
  int frames() const { return frames_; }
  double coarse() const { return std::sqrt(coarse2_ / frames_); }
  double subdivided() const { return std::sqrt(subdivided2_ / frames_); }
  double refined() const { return std::sqrt(refined2_ / frames_); }

 private:
  double coarse2_ = 0.0, subdivided2_ = 0.0, refined2_ = 0.0;
  int frames_ = 0;
};

// The run's error and flicker figures, from those of its frames.
void SetRunFigures(const RmsOverFrames& errors, const RmsOverFrames& flicker,
                   SequenceResult* result) {
  result->measured = errors.frames();
  result->rms_coarse_mm = errors.coarse();
  result->rms_subdivided_mm = errors.subdivided();
  result->rms_refined_mm = errors.refined();
  result->flickered = flicker.frames();
  result->flicker_coarse_mm = flicker.coarse();
  result->flicker_subdivided_mm = flicker.subdivided();
  result->flicker_refined_mm = flicker.refined();
}

// One run over the frames: what stays fixed while they are refined.
class SequenceRun {
 public:
  SequenceRun(Capture* capture, const SequenceOptions& options, const std::string& out,
              SequenceObserver* observer)
      : capture_(capture),
        options_(options),
        out_(out),
        observer_(observer),
        log_(out, capture->frame_names(), options.mesh_format),
        model_(capture->ReadCoarseMesh(0), capture->vertex_mask(), options.refine,
               capture->mesh_path(0)),
        reader_(capture, options.skip_unreadable_cameras, options.held_out_cameras,
                options.refine.image,
                [this](int frame, FrameReadAhead::Frame* read) { WorkAhead(frame, read); }),
        reference_colors_(LoadColors()),
        regions_(SplitByTexture(model_, *capture)) {}
  // The reader's work ahead uses this run's members.
  ~SequenceRun() { reader_.DropPending(); }

  // The size of the first frame's problem and what it forecasts, before the long part of the
  // run and before it writes anything: a run that would need more memory than it may take is
  // refused here.
  void ReportProblemSize(const FrameRange& frames) {
    FrameReadAhead::Frame first = reader_.Take(frames.begin);
    ProblemSize size = EstimateProblemSize(model_, reference_colors_, first.input, options_.refine,
                                           frames.size(), UndistortedPixels(*capture_));
    AddHeldOutScoring(first.held_out, static_cast<int>(first.input.cameras.size()),
                      options_.held_out_score.neighbours, &size);
    const AvailableMemory available = ReadAvailableMemory();
    RequireMemoryFor(size, frames.size(), options_.refine, options_.max_memory_mb, available);
    observer_->Starting(frames.size(), first.input, size);
    const double limit = MemoryLimitMb(options_.max_memory_mb, available);
    if (size.widest_peak_memory_mb > limit) observer_->WidestRangeMayNotFit(size, limit);
    reader_.Keep(frames.begin, std::move(first));
  }

  void Run(const FrameRange& frames, SequenceResult* result) {
    if (!FollowsColors(options_)) RequireNoFollowedColors();
    SaveColors();
    prepare_ahead_ = !FollowsColors(options_);
    RmsOverFrames errors, flicker;
    double confident_share_sum = 0.0;
    int confident_shares = 0;
    for (int frame = frames.begin; frame < frames.end; ++frame) {
      if (Done(frame)) {
        observer_->FrameAlreadyDone(capture_->frame_name(frame));
        ++result->already_done;
        continue;
      }
      const FrameStats stats = RefineOne(frame, frames);
      ++result->refined;
      if (std::isfinite(stats.confident_share)) {
        confident_share_sum += stats.confident_share;
        ++confident_shares;
      }
      if (std::isfinite(stats.rms_refined_mm)) {
        errors.Add(stats.rms_coarse_mm, stats.rms_subdivided_mm, stats.rms_refined_mm);
      }
      if (std::isfinite(stats.flicker_refined_mm)) {
        flicker.Add(stats.flicker_coarse_mm, stats.flicker_subdivided_mm, stats.flicker_refined_mm);
      }
      observer_->FrameRefined(stats);
    }
    SetRunFigures(errors, flicker, result);
    result->confident_share =
        confident_shares > 0 ? confident_share_sum / confident_shares : std::nan("");
  }

 private:
  ReferenceColors LoadColors() {
    const std::string path = ReferenceColorsPath(out_);
    const int frame = options_.reference_frame;
    if (fs::exists(path) || frame >= capture_->num_frames()) {
      return LoadOrComputeReferenceColors(model_, options_, capture_, path);
    }
    FrameReadAhead::Frame reference = reader_.Take(frame);
    ReportSkipped(frame, reference.skipped);
    // Saved by SaveColors, once the run is known to fit in memory.
    ReferenceColors colors =
        ComputeReferenceFrameColors(model_, options_, capture_, reference.input);
    colors.recipe = ReferenceColorRecipe(options_);
    colors_unsaved_ = true;
    reader_.Keep(frame, std::move(reference));
    return colors;
  }

  // Writes the reference colours this run computed, and takes them as saved, so that every run
  // and shard on this folder starts from the very same colours; those of a shard that saved
  // them first when there are.
  void SaveColors() {
    if (!colors_unsaved_) return;
    const std::string path = ReferenceColorsPath(out_);
    if (!fs::exists(path)) WriteReferenceColors(path, reference_colors_);
    reference_colors_ = LoadOrComputeReferenceColors(model_, options_, capture_, path);
    colors_unsaved_ = false;
  }

  void ReportSkipped(int frame, const std::vector<SkippedCamera>& skipped) {
    for (const SkippedCamera& camera : skipped) {
      observer_->CameraSkipped(capture_->frame_name(frame), camera);
    }
  }

  bool Done(int frame) const {
    return FrameDone(FrameFilesIn(out_, capture_->frame_name(frame), options_.mesh_format));
  }

  // A folder whose frames followed their colours cannot be continued with fixed colours.
  void RequireNoFollowedColors() const {
    const std::string folder = FollowedColorsFolder(out_);
    Require(!fs::exists(folder) || fs::is_empty(folder), folder,
            "holds the colours of a run with ReferenceColorOptions::follow_colors, but this config "
            "keeps the "
            "colours fixed: use another output folder");
  }

  // The colours `frame` is refined with: the reference colours, or, when they follow the
  // sequence, those that the frame before left in the run folder.
  ReferenceColors ColorsFor(int frame) const {
    if (!FollowsColors(options_) || frame <= options_.reference_frame) return reference_colors_;
    const std::string& previous = capture_->frame_name(frame - 1);
    Require(Done(frame - 1), out_,
            "ReferenceColorOptions::follow_colors: frame " + capture_->frame_name(frame) +
                " follows the colours that frame " + previous +
                " leaves, which is not done here; following is sequential: refine the frames in "
                "order from the reference frame, without shards");
    const std::string path = FollowedColorsPath(out_, previous);
    Require(
        fs::exists(path), path,
        "is missing: frame " + previous +
            " was refined without ReferenceColorOptions::follow_colors; use another output folder");
    ReferenceColors colors = ReadReferenceColors(path, model_.num_fine_vertices());
    const std::string wanted = FollowedColorRecipe(options_);
    Require(
        colors.recipe == wanted, path,
        "was made with " + RecipeDifference(colors.recipe, wanted) + ": use another output folder");
    return colors;
  }

  // Saves the colours the frame after `name` is refined with: `used` followed towards the
  // colours of the frame's refined surface, or `used` as it was when the frame was flagged worse.
  void SaveFollowedColors(const std::string& name, const ReferenceColors& used,
                          const FrameInput& input, const FrameResult& result, bool worse) const {
    ReferenceColors next = used;
    if (!worse) {
      next = FollowColors(used, ComputeSurfaceColors(result.refined, input, options_.refine),
                          reference_colors_, options_.colors);
    }
    next.recipe = FollowedColorRecipe(options_);
    WriteReferenceColors(FollowedColorsPath(out_, name), next);
  }

  // On the reader's thread, while the frame before is solved: what refining `frame` needs that no
  // other frame's result changes.
  void WorkAhead(int frame, FrameReadAhead::Frame* read) const {
    // The truth first: building its ray caster runs on one thread, and while the frame before is
    // still being solved that leaves no core idle; last, it would when that solve ends first.
    read->truth = TrueFineGroundTruth(*capture_, model_, read->input.coarse, frame);
    if (prepare_ahead_) {
      read->prepared = PrepareFrameAhead(model_, reference_colors_, &read->input, options_.refine);
      // Beside the refinement only the held-out score reads the pixels after this: two frames'
      // images are a run's largest buffers.
      if (DropsImagesAhead()) {
        read->input.images.clear();
        read->input.masks.clear();
      }
    }
  }

  // Whether the work ahead prepares each frame and then lets go of its images.
  bool DropsImagesAhead() const {
    return prepare_ahead_ && options_.held_out_cameras.empty() &&
           !ReadsImagesAfterPreparation(options_.refine);
  }

  // Starts reading the first frames after `frame` that are still to do: two when the frames read
  // ahead are prepared without their images, else one. A frame's preparation and the solve of
  // the one before share the cores, and each takes longer on some frames than on others; with one
  // frame ahead, the reader waited for the solve on some frames and the solve for the reader on
  // others, and one core in seven was idle on synth_skirt (30 frames: 200 -> 214 frames per
  // minute with two). A frame kept with its images would hold them all the while; prepared
  // without them, the second frame ahead cost synth_skirt's runs ~6 MB of peak memory.
  void ReadAheadAfter(int frame, const FrameRange& frames) {
    int wanted = DropsImagesAhead() ? 2 : 1;
    for (int next = frame + 1; next < frames.end && wanted > 0; ++next) {
      if (Done(next)) continue;
      reader_.ReadAhead(next);
      --wanted;
    }
  }

  FrameStats RefineOne(int frame, const FrameRange& frames) {
    const std::string& name = capture_->frame_name(frame);
    const auto start = std::chrono::steady_clock::now();
    const double cpu_seconds_at_start = ProcessCpuSeconds();
    FrameReadAhead::Frame read = reader_.Take(frame);
    ReportSkipped(frame, read.skipped);
    FrameInput& input = read.input;
    const std::vector<CalibratedImage>& held_out = read.held_out;
    const std::vector<SkippedCamera>& skipped = read.skipped;
    ReadAheadAfter(frame, frames);
    const bool pulled = NeedsOf(options_.refine.energy).reads_frame_before;
    const Eigen::VectorXd before = options_.refine.warm_start || pulled
                                       ? SolvedFrameBefore(out_, *capture_, frame, options_, model_)
                                       : Eigen::VectorXd();
    const Eigen::VectorXd warm_start = options_.refine.warm_start ? before : Eigen::VectorXd();
    if (pulled) input.frame_before_k = before;
    if (options_.refine.energy.consensus.shared_appearance) {
      input.frame_before_appearance = AppearanceBefore(frame);
    }
    const ReferenceColors colors = ColorsFor(frame);
    RefineOptions refine = options_.refine;
    if (prepare_ahead_ && reader_.ReadsAhead()) {
      refine.solver = SolverOptionsBesideWorkAhead(refine.solver);
    }
    FrameResult result = warm_start.size() > 0
                             ? RefineFrameFrom(model_, colors, input, refine, warm_start,
                                               std::move(read.prepared), &solver_workspace_)
                             : RefineFrame(model_, colors, input, refine, nullptr,
                                           std::move(read.prepared), &solver_workspace_);
    if (result.num_surface_gaussians == 0) observer_->NothingToRefine(name);

    FrameStats stats = MakeFrameStats(name, options_.refine, result);
    for (const SkippedCamera& camera : skipped) stats.skipped_cameras.push_back(camera.camera);
    ScoreInHeldOutViews(options_, model_, input, held_out, &result, &stats);
    AddGroundTruthErrors(read.truth, regions_, result, &stats);
    FrameErrors errors{frame, SignedErrorsAgainst(read.truth, result.k)};
    if (!errors.errors.empty()) AddFlicker(ErrorsBefore(frame), errors.errors, regions_, &stats);
    // Before the record, which marks the frame done: a done frame always has them.
    if (FollowsColors(options_) && frame >= options_.reference_frame) {
      SaveFollowedColors(name, colors, input, result, stats.worse);
    }
    if (result.appearance.cols() > 0) {
      WriteAppearance(AppearancePath(out_, name), result.appearance);
    }
    WriteFrame(FrameFilesIn(out_, name, options_.mesh_format), result, options_.mesh_format, &stats,
               start, cpu_seconds_at_start, log_);
    last_errors_ = std::move(errors);
    return stats;
  }

  // The appearance the frame before `frame` showed at its surface samples, from its saved file
  // (energy.consensus.shared_appearance), so that a resumed run or a shard compares its first
  // frame's patches with what a run that never stopped compares them with; empty when that frame
  // is not done here or left no appearance.
  Eigen::Matrix3Xd AppearanceBefore(int frame) const {
    if (frame == 0) return {};
    const std::string& previous = capture_->frame_name(frame - 1);
    const std::string path = AppearancePath(out_, previous);
    if (!FrameDone(FrameFilesIn(out_, previous, options_.mesh_format)) || !fs::exists(path)) {
      return {};
    }
    return ReadAppearance(path);
  }

  // The signed errors of the frame before `frame`: those this run just measured, else from that
  // frame's saved displacement and its truth, which give the very same numbers (the displacement
  // file reads back to the same doubles), so that a resumed run or a shard measures its first
  // frame's flicker as a run that never stopped does. Empty when that frame is not done here or
  // has no truth.
  SignedErrors ErrorsBefore(int frame) const {
    if (frame == 0) return {};
    if (last_errors_.frame == frame - 1) return last_errors_.errors;
    const FrameFiles files =
        FrameFilesIn(out_, capture_->frame_name(frame - 1), options_.mesh_format);
    if (!FrameDone(files) || !capture_->HasTrueSurface(frame - 1)) return {};
    const Eigen::VectorXd k = ReadDisplacement(files.displacement, model_.num_fine_vertices());
    return SignedErrorsAgainst(
        TrueFineGroundTruth(*capture_, model_, capture_->ReadCoarseMesh(frame - 1), frame - 1), k);
  }

  Capture* capture_;
  const SequenceOptions& options_;
  const std::string out_;
  SequenceObserver* observer_;
  const StatsLog log_;
  const SequenceModel model_;
  // Whether the reader prepares each frame it reads: not until the colours are known and the
  // first frame measured for the forecast, nor when each frame's colours follow the frame before.
  // Before the reader, which reads the reference frame while the run is made.
  bool prepare_ahead_ = false;
  // Whether the colours were computed by this run and are still to be written (SaveColors).
  // Before the colours, which set it as they are made.
  bool colors_unsaved_ = false;
  // Before the colours: the reference frame they are taken from is read by it and kept for the
  // run (FrameReadAhead::Keep).
  FrameReadAhead reader_;
  // Computed by this run and not yet written (SaveColors), or read from the run folder.
  ReferenceColors reference_colors_;
  const Regions regions_;
  // The solver's problem, taken over by each frame from the one before (SolverWorkspace).
  SolverWorkspace solver_workspace_;
  // The signed errors of the frame this run refined last, for the flicker of the next.
  FrameErrors last_errors_;
};

}  // namespace

const OptionFields<SequenceOptions>& SequenceOptions::Fields() {
  static const OptionFields<SequenceOptions> fields = [] {
    OptionFields<SequenceOptions> f;
    f.AddInt("reference_frame", &SequenceOptions::reference_frame,
             "Frame (index in the sorted frame list) whose images colour the surface Gaussians; "
             "the paper: the first.",
             0);
    f.AddInt("max_memory_mb", &SequenceOptions::max_memory_mb,
             "finecap refine: refuse, before it starts, a run whose forecast peak memory exceeds "
             "this many MB; 0 = the memory available (the smaller of the cgroup limit and "
             "MemAvailable), which is always checked.",
             0);
    return f;
  }();
  return fields;
}

void SequenceOptions::Check() const {
  refine.Check();
  colors.Check();
  held_out_score.Check();
  Fields().CheckValues(*this, "SequenceOptions::");
  for (const std::string& camera : held_out_cameras) {
    Require(!camera.empty(), "SequenceOptions::held_out_cameras", "holds an empty camera name");
  }
}

std::string ReferenceColorRecipe(const SequenceOptions& options) {
  const RefineOptions& refine = options.refine;
  std::ostringstream recipe;
  recipe.precision(17);
  recipe << "reference_frame=" << options.reference_frame
         << " subdivision_levels=" << refine.subdivision_levels << " sigma_hat=" << refine.sigma_hat
         << " reference_colors=" << refine.reference_colors
         << " color_space=" << ColorSpaceName(refine.image.color_space)
         << " max_depth=" << refine.image.max_depth
         << " min_leaf_size=" << refine.image.min_leaf_size
         << " split_threshold=" << refine.image.split_threshold
         << " depth_tolerance=" << refine.visibility.depth_tolerance
         << " max_view_angle_deg=" << refine.visibility.max_view_angle_deg
         << " border_margin=" << refine.visibility.border_margin
         << " overlap=" << refine.energy.overlap << " reach_sigmas=" << refine.energy.reach_sigmas
         << " held_out=";
  for (size_t c = 0; c < options.held_out_cameras.size(); ++c) {
    recipe << (c == 0 ? "" : ",") << options.held_out_cameras[c];
  }
  // Only when not the default (and below only when refined), so that the recipes of files saved
  // before these choices existed still fit.
  if (refine.subdivision != SubdivisionScheme::kLoop)
    recipe << " subdivision=" << refine.subdivision;
  if (TakesColorsAtRefinedSurface(options)) {
    recipe << " reference_surface=refined reg_rings=" << refine.energy.reg_rings;
  }
  return recipe.str();
}

SolverOptions SolverOptionsBesideWorkAhead(const SolverOptions& configured) {
  SolverOptions options = configured;
  options.num_threads = std::max(1, configured.Threads() - 1);
  return options;
}

std::string FollowedColorRecipe(const SequenceOptions& options) {
  std::ostringstream recipe;
  recipe.precision(17);
  recipe << ReferenceColorRecipe(options) << " follow_colors=" << options.colors.follow_colors
         << " follow_anchor=" << options.colors.follow_anchor;
  return recipe.str();
}

RefineOptions ReferencePassOptions(const RefineOptions& configured, const Capture& capture,
                                   int reference_frame) {
  RefineOptions pass;
  pass.subdivision_levels = configured.subdivision_levels;
  pass.subdivision = configured.subdivision;
  pass.energy.reg_rings = configured.energy.reg_rings;
  pass.solver.num_threads = configured.solver.num_threads;
  ResolveSceneScaleDefaults(capture, reference_frame, &pass);
  return pass;
}

ReferenceColors FollowColors(const ReferenceColors& previous, const ReferenceColors& frame,
                             const ReferenceColors& reference,
                             const ReferenceColorOptions& options) {
  const size_t n = reference.colors.size();
  Require(previous.colors.size() == n && frame.colors.size() == n, "FollowColors",
          "colours of " + std::to_string(previous.colors.size()) + " and " +
              std::to_string(frame.colors.size()) + " vertices for a reference of " +
              std::to_string(n));
  const float rate = static_cast<float>(options.follow_colors);
  const float anchor = static_cast<float>(options.follow_anchor);
  ReferenceColors next = previous;
  for (size_t v = 0; v < n; ++v) {
    if (!reference.valid[v]) continue;
    Eigen::Vector3f color = previous.colors[v];
    if (frame.valid[v]) color += rate * (frame.colors[v] - color);
    next.colors[v] = color + anchor * (reference.colors[v] - color);
  }
  return next;
}

ReferenceColors LoadOrComputeReferenceColors(const SequenceModel& model,
                                             const SequenceOptions& options, Capture* capture,
                                             const std::string& path,
                                             std::vector<SkippedCamera>* skipped) {
  if (fs::exists(path)) {
    ReferenceColors saved = ReadReferenceColors(path, model.num_fine_vertices());
    RequireSameRecipe(saved, options, path);
    return saved;
  }
  Require(options.reference_frame < capture->num_frames(), "SequenceOptions::reference_frame",
          "frame " + std::to_string(options.reference_frame) + " does not exist in " +
              capture->directory());
  FrameInput reference =
      ReadFrameInput(capture, options.reference_frame, options.skip_unreadable_cameras, skipped);
  TakeHeldOutViews(options.held_out_cameras, &reference);  // Held-out cameras colour nothing.
  return SaveReferenceColors(model, options, capture, reference, path);
}

ReferenceColors SaveReferenceColors(const SequenceModel& model, const SequenceOptions& options,
                                    Capture* capture, const FrameInput& reference,
                                    const std::string& path) {
  ReferenceColors colors = ComputeReferenceFrameColors(model, options, capture, reference);
  colors.recipe = ReferenceColorRecipe(options);
  WriteReferenceColors(path, colors);
  // As saved: every run and shard on this folder then starts from the very same colours.
  return ReadReferenceColors(path, model.num_fine_vertices());
}

FineGroundTruth TrueFineGroundTruth(const Capture& capture, const SequenceModel& model,
                                    const Mesh& coarse, int frame) {
  if (!capture.HasTrueSurface(frame)) return {};
  const Mesh fine = model.Subdivide(coarse);
  const Eigen::Matrix3Xd normals = ComputeVertexNormals(fine);
  const Eigen::Index n = fine.num_vertices();
  // Both point sets in one cast: the truth's ray caster is built once.
  Eigen::Matrix3Xd points(3, 2 * n), directions(3, 2 * n);
  points << fine.vertices, model.Interpolate(coarse).vertices;
  directions << normals, normals;
  const Eigen::VectorXd distances =
      TrueDisplacementAlongNormals(points, directions, capture.ReadTrueSurface(frame), 0.1);
  return {distances.head(n), distances.tail(n)};
}

Eigen::VectorXd ReadSolvedDisplacement(const FrameFiles& files, int num_fine_vertices,
                                       const RefineOptions& options) {
  return SolvedDisplacement(ReadDisplacement(files.displacement, num_fine_vertices),
                            ReadFrameStats(files.stats).kept_input, options);
}

SequenceResult RefineSequence(Capture* capture, const FrameRange& frames,
                              const SequenceOptions& options, const std::string& out,
                              SequenceObserver* observer) {
  options.Check();
  SequenceObserver silent;
  if (observer == nullptr) observer = &silent;
  const StatsLog log(out, capture->frame_names(), options.mesh_format);
  const auto prepare_folder = [&] {
    const int stale = PrepareRunSubfolders(out, FollowsColors(options),
                                           options.refine.energy.consensus.shared_appearance);
    if (stale > 0) observer->StaleFilesRemoved(stale);
    log.Rebuild();
  };
  SequenceResult result;
  if (frames.size() == 0) {
    prepare_folder();
    return result;
  }
  // The run is made and its memory forecast before the folder is touched: a refused run writes
  // nothing.
  SequenceRun run(capture, options, out, observer);
  run.ReportProblemSize(frames);
  prepare_folder();
  run.Run(frames, &result);
  log.Rebuild();
  return result;
}

}  // namespace finecap
