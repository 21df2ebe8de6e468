#include "commands/command_util.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "finecap/io/mesh_io.h"
#include "finecap/util/error.h"

namespace finecap {
namespace internal {

namespace fs = std::filesystem;

namespace {

bool IsHeldOut(const Config& config, const std::string& camera) {
  const std::vector<std::string>& names = config.validation.cameras;
  return std::find(names.begin(), names.end(), camera) != names.end();
}

// Every name of validation.cameras is a camera of the rig, and at least one camera is left to
// refine with.
void CheckHeldOutCameras(const Config& config, const Capture& capture) {
  std::string rig;
  for (const Camera& camera : capture.cameras()) rig += (rig.empty() ? "" : ", ") + camera.name;
  for (const std::string& name : config.validation.cameras) {
    bool found = false;
    for (const Camera& camera : capture.cameras()) found = found || camera.name == name;
    Require(
        found, "validation.cameras",
        "'" + name + "' is not a camera of " + capture.directory() + " (its cameras: " + rig + ")");
  }
  int training = 0;
  for (const Camera& camera : capture.cameras()) training += IsHeldOut(config, camera.name) ? 0 : 1;
  Require(training > 0, "validation.cameras",
          "holds out every camera of " + capture.directory() + ": none is left to refine with");
}

}  // namespace

Capture OpenConfiguredCapture(const Config& config) {
  Require(!config.capture.dir.empty(), "capture.dir",
          "no capture folder given (set capture.dir or pass --capture DIR)");
  Capture capture = Capture::Open(config.capture.dir, config.capture.mesh);
  CheckHeldOutCameras(config, capture);
  return capture;
}

FrameRange ConfiguredFrames(const Config& config, const Capture& capture) {
  const FrameRange range = config.frame_range().ClippedTo(capture.num_frames());
  Require(range.size() > 0, "capture.frames",
          "'" + config.capture.frames + "' selects no frame of " + capture.directory() +
              ", which has " + std::to_string(capture.num_frames()));
  return range;
}

Config WithSceneLengths(const Config& config, const Capture& capture, const std::string& command,
                        SceneScaleDefaults* defaults) {
  // A sigma_hat that follows from the scene fits any mesh, so the unit check measures the mesh
  // against the person-sized value: a capture in millimetres is still told apart.
  const double unit_check_sigma_hat =
      config.refine.scene_lengths.sigma_hat ? RefineOptions().sigma_hat : config.refine.sigma_hat;
  RequirePlausibleSceneScale(capture.ReadCoarseMesh(0), unit_check_sigma_hat, capture.mesh_path(0));
  Config resolved = config;
  const SceneScaleDefaults chosen =
      ResolveSceneScaleDefaults(capture, config.reference_frame, &resolved.refine);
  std::cerr << "finecap " << command << ": " << InConfigTerms(DescribeSceneScaleDefaults(chosen))
            << "\n";
  if (defaults != nullptr) *defaults = chosen;
  resolved.refine.Check();
  return resolved;
}

std::string RoundedCount(double count) {
  std::ostringstream text;
  if (count >= 1e6) {
    text.precision(count >= 1e7 ? 0 : 1);
    text << std::fixed << count / 1e6 << " M";
  } else {
    text << std::lround(count);
  }
  return text.str();
}

std::string WidestRangeForecast(const ProblemSize& size) {
  if (!(size.widest_peak_memory_mb > size.peak_memory_mb)) return "";
  return " (up to " + std::to_string(std::lround(size.widest_peak_memory_mb)) +
         " MB if a frame's plane sweep widens its search range to " +
         LengthText(size.widest_k_max) + ")";
}

std::string TooFewViewsReason(double share) {
  return "only " + std::to_string(std::lround(100.0 * share)) +
         " % of its surface is seen well enough by enough cameras near enough to each other "
         "(visibility.*, energy.consensus.min_cameras)";
}

std::string RoundedSeconds(double seconds) {
  std::ostringstream text;
  text.precision(seconds < 10.0 || (seconds >= 60.0 && seconds < 600.0) ? 1 : 0);
  text << std::fixed;
  if (seconds < 60.0) {
    text << seconds << " s";
  } else {
    text << seconds / 60.0 << " min";
  }
  return text.str();
}

std::string CheckOutputFolder(const Config& config, const Capture& capture) {
  Require(!config.output.dir.empty(), "output.dir",
          "no output folder given (set output.dir or pass --out DIR)");
  const fs::path out = fs::weakly_canonical(config.output.dir);
  const fs::path in = fs::weakly_canonical(capture.directory());
  const auto [mismatch, unused] = std::mismatch(in.begin(), in.end(), out.begin(), out.end());
  Require(mismatch != in.end(), config.output.dir,
          "the output folder may not be the capture folder or lie inside it");
  return out.string();
}

std::string PrepareOutputFolder(const Config& config, const Capture& capture) {
  const fs::path out = CheckOutputFolder(config, capture);
  std::error_code error;
  fs::create_directories(out, error);
  // A concurrent shard may create it at the same moment: what matters is that it exists.
  Require(fs::is_directory(out), config.output.dir,
          "cannot create the output folder: " + error.message());
  return out.string();
}

std::string RefinedRunFolder(const Config& config) {
  Require(!config.output.dir.empty(), "output.dir",
          "no folder of a refined run given (set output.dir or pass --out DIR)");
  Require(fs::is_directory(config.output.dir), config.output.dir,
          "no such folder: run finecap refine first");
  return fs::canonical(config.output.dir).string();
}

SequenceOptions SequenceOptionsOf(const Config& config) {
  SequenceOptions options;
  options.refine = config.refine;
  options.reference_frame = config.reference_frame;
  options.colors = config.colors;
  options.held_out_cameras = config.validation.cameras;
  options.held_out_score = config.validation.score;
  options.skip_unreadable_cameras = config.capture.skip_unreadable_cameras;
  options.mesh_format = MeshFormatOf(config);
  options.max_memory_mb = config.runtime.max_memory_mb;
  return options;
}

MeshFormat MeshFormatOf(const Config& config) {
  return config.output.mesh_format == "obj" ? MeshFormat::kObj : MeshFormat::kPly;
}

namespace {

void WarnSkipped(const std::string& frame, const SkippedCamera& camera) {
  std::cerr << "finecap: warning: frame " << frame << " without camera " << camera.camera
            << " (capture.skip_unreadable_cameras): " << camera.error << "\n";
}

// A sequence's progress as `finecap <command>` shows it.
class ConsoleObserver : public SequenceObserver {
 public:
  ConsoleObserver(const std::string& command, int num_frames)
      : command_(command), progress_(num_frames) {}

  void StaleFilesRemoved(int count) override {
    std::cerr << "finecap " << command_ << ": removed " << count << " files a killed run left\n";
  }
  void Starting(int num_frames, const FrameInput& first, const ProblemSize& size) override {
    const Camera& camera = first.cameras.front();
    std::cerr << "finecap " << command_ << ": " << num_frames << " frames, " << first.cameras.size()
              << " cameras of " << camera.width << "x" << camera.height << ", "
              << size.num_surface_gaussians << " surface Gaussians (of " << size.num_fine_vertices
              << " vertices after subdivision), about " << RoundedCount(size.num_pairs)
              << " pairs; expected peak memory " << std::lround(size.peak_memory_mb) << " MB"
              << WidestRangeForecast(size) << ", about " << RoundedSeconds(size.seconds_per_frame)
              << " per frame\n";
  }
  void WidestRangeMayNotFit(const ProblemSize& size, double limit_mb) override {
    std::cerr << "finecap " << command_ << ": warning: a frame whose plane sweep widens its "
              << "search range to " << LengthText(size.widest_k_max) << " would need about "
              << std::lround(size.widest_peak_memory_mb) << " MB, more than the "
              << std::lround(limit_mb) << " MB the run may take; lower "
              << "refine.sweep.max_widenings to keep every frame within it\n";
  }
  void CameraSkipped(const std::string& frame, const SkippedCamera& camera) override {
    WarnSkipped(frame, camera);
  }
  void NothingToRefine(const std::string& frame) override {
    std::cerr << "finecap " << command_ << ": warning: frame " << frame
              << ": no camera sees any vertex to refine (the mesh is behind every camera or "
                 "out of view); the input surface is written\n";
  }
  void FrameAlreadyDone(const std::string& frame) override { progress_.FrameDone(frame, true, ""); }
  void FrameRefined(const FrameStats& stats) override {
    std::ostringstream detail;
    detail.precision(3);
    detail << "E " << stats.energy_start << " -> " << stats.energy_end << ", " << stats.iterations
           << " iterations";
    if (std::isfinite(stats.heldout_ncc_input)) {
      detail << ", held-out NCC " << stats.heldout_ncc_input << " (subdivided "
             << stats.heldout_ncc_subdivided << ") -> " << stats.heldout_ncc_refined;
    }
    detail << (stats.worse ? ", WORSE" : "") << (stats.kept_input ? " (input kept)" : "");
    if (std::isfinite(stats.rms_refined_mm)) {
      detail << ", RMS vs truth " << stats.rms_coarse_mm << " (subdivided "
             << stats.rms_subdivided_mm << ") -> " << stats.rms_refined_mm << " mm";
    }
    if (std::isfinite(stats.flicker_refined_mm)) {
      detail << ", flicker " << stats.flicker_subdivided_mm << " -> " << stats.flicker_refined_mm
             << " mm";
    }
    if (std::isfinite(stats.confident_share)) {
      detail << ", " << std::lround(100.0 * stats.confident_share) << " % confident";
    }
    progress_.FrameDone(stats.frame, false, detail.str());
  }

 private:
  std::string command_;
  Progress progress_;
};

void PrintConfidence(double confident_share) {
  if (!std::isfinite(confident_share)) return;
  const long percent = std::lround(100.0 * confident_share);
  std::cout << "Refined with confidence: " << percent
            << " % of the refined vertices (mean over the frames run now); the rest, seen by too "
               "few cameras, only at steep angles, or plain, stay near the input\n";
  if (confident_share < kUsefulConfidentShare) {
    std::cout << "Too few views for this capture to be refined usefully: "
              << TooFewViewsReason(confident_share) << "; the rest is kept near the input\n";
  }
}

}  // namespace

ReferenceColors ConfiguredReferenceColors(const Config& config, const SequenceModel& model,
                                          Capture* capture, const std::string& out) {
  std::vector<SkippedCamera> skipped;
  ReferenceColors colors = LoadOrComputeReferenceColors(model, SequenceOptionsOf(config), capture,
                                                        ReferenceColorsPath(out), &skipped);
  for (const SkippedCamera& camera : skipped) {
    WarnSkipped(capture->frame_name(config.reference_frame), camera);
  }
  return colors;
}

void RefineConfiguredSequence(const Config& config, const FrameRange& frames,
                              const std::string& out, const std::string& command,
                              Capture* capture) {
  ConsoleObserver observer(command, frames.size());
  const SequenceResult result =
      RefineSequence(capture, frames, SequenceOptionsOf(config), out, &observer);
  if (frames.size() == 0) {
    std::cout << "Shard " << config.runtime.shard.ToString() << " holds none of the "
              << ConfiguredFrames(config, *capture).size() << " configured frames\n";
    return;
  }
  std::cout << "Refined meshes: " << out << "/meshes/, displacements: " << out
            << "/k/, statistics: " << out << "/stats.jsonl\n";
  PrintConfidence(result.confident_share);
  if (result.measured > 0) {
    std::cout.precision(3);
    std::cout << "Error against the ground truth (textured region, RMS over the frames run now): "
              << "input as given " << result.rms_coarse_mm << " mm (subdivided "
              << result.rms_subdivided_mm << " mm), refined " << result.rms_refined_mm
              << " mm, detail recovered "
              << 100.0 * (1.0 - result.rms_refined_mm / result.rms_coarse_mm) << " %\n";
  }
  if (result.flickered > 0) {
    std::cout << "Flicker (RMS change of the signed error from one frame to the next, over the "
              << result.flickered << " frames run now that follow a done frame): input as given "
              << result.flicker_coarse_mm << " mm (subdivided " << result.flicker_subdivided_mm
              << " mm), refined " << result.flicker_refined_mm << " mm, "
              << result.flicker_refined_mm / result.rms_refined_mm << " of the refined error\n";
  }
}

std::vector<RefinedFrame> FindRefinedFrames(const Config& config, const Capture& capture,
                                            const std::string& out) {
  return finecap::FindRefinedFrames(out, capture.frame_names(), ConfiguredFrames(config, capture),
                                    MeshFormatOf(config), capture.directory());
}

Progress::Progress(int total)
    : total_(total), terminal_(isatty(fileno(stderr))), last_(std::chrono::steady_clock::now()) {}

void Progress::FrameDone(const std::string& name, bool skipped, const std::string& detail) {
  const auto now = std::chrono::steady_clock::now();
  ++done_;
  if (!skipped) {
    seconds_ += std::chrono::duration<double>(now - last_).count();
    ++timed_;
  }
  last_ = now;
  const double per_frame = timed_ > 0 ? seconds_ / timed_ : 0.0;
  char line[256];
  std::snprintf(line, sizeof(line), "frame %d/%d (%s) %s| %.1f s/frame, %.0f s left", done_, total_,
                name.c_str(), skipped ? "already done " : "", per_frame,
                per_frame * (total_ - done_));
  if (terminal_) {
    std::cerr << "\r\033[K" << line << (done_ == total_ ? "\n" : "") << std::flush;
  } else {
    std::cerr << line << (detail.empty() ? "" : " | " + detail) << "\n";
  }
}

}  // namespace internal
}  // namespace finecap
