#include "commands/command_util.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "commands/run_folder.h"
#include "finecap/error.h"
#include "finecap/ground_truth.h"
#include "io_util.h"

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
  Capture capture = Capture::Open(config.capture.dir);
  CheckHeldOutCameras(config, capture);
  return capture;
}

std::vector<CalibratedImage> TakeHeldOutViews(const Config& config, FrameInput* input) {
  std::vector<CalibratedImage> held_out;
  FrameInput training;
  training.coarse = std::move(input->coarse);
  for (size_t c = 0; c < input->cameras.size(); ++c) {
    if (IsHeldOut(config, input->cameras[c].name)) {
      held_out.push_back({input->cameras[c], input->images[c]});
    } else {
      training.cameras.push_back(input->cameras[c]);
      training.images.push_back(input->images[c]);
    }
  }
  *input = std::move(training);
  Require(!input->cameras.empty(), "validation.cameras",
          "no camera other than the held-out ones could be read");
  return held_out;
}

std::vector<CalibratedImage> CalibratedImagesOf(const FrameInput& input) {
  std::vector<CalibratedImage> views;
  for (size_t c = 0; c < input.cameras.size(); ++c) {
    views.push_back({input.cameras[c], input.images[c]});
  }
  return views;
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
  std::cerr << "finecap " << command << ": " << DescribeSceneScaleDefaults(chosen) << "\n";
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

std::string PrepareOutputFolder(const Config& config, const Capture& capture) {
  Require(!config.output.dir.empty(), "output.dir",
          "no output folder given (set output.dir or pass --out DIR)");
  const fs::path out = fs::weakly_canonical(config.output.dir);
  const fs::path in = fs::weakly_canonical(capture.directory());
  const auto [mismatch, unused] = std::mismatch(in.begin(), in.end(), out.begin(), out.end());
  Require(mismatch != in.end(), config.output.dir,
          "the output folder may not be the capture folder or lie inside it");
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

FrameInput ReadFrameInput(Capture* capture, int frame) {
  return ReadFrameInput(capture, frame, false, nullptr);
}

FrameInput ReadFrameInput(Capture* capture, int frame, bool skip_unreadable,
                          std::vector<std::string>* skipped) {
  FrameInput input;
  input.coarse = capture->ReadCoarseMesh(frame);
  std::string first_error;
  for (int c = 0; c < capture->num_cameras(); ++c) {
    const Camera& camera = capture->cameras()[c];
    try {
      input.images.push_back(capture->ReadImage(c, frame));
      input.cameras.push_back(camera);
    } catch (const Error& error) {
      if (!skip_unreadable) throw;
      if (first_error.empty()) first_error = error.what();
      std::cerr << "finecap: warning: frame " << capture->frame_name(frame) << " without camera "
                << camera.name << " (capture.skip_unreadable_cameras): " << error.what() << "\n";
      if (skipped != nullptr) skipped->push_back(camera.name);
    }
  }
  Require(!input.cameras.empty(), "",
          first_error + " (and no other camera's image of frame " + capture->frame_name(frame) +
              " could be read either)");
  return input;
}

ReferenceColors LoadOrComputeReferenceColors(const Config& config, const SequenceModel& model,
                                             Capture* capture, const std::string& path) {
  if (fs::exists(path)) {
    ReferenceColors saved = ReadReferenceColors(path, model.num_fine_vertices());
    const RefineOptions& options = config.refine;
    // The file holds sigma_hat to 9 significant digits, which a length chosen from the scene
    // needs all of.
    Require(saved.color_space == options.image.color_space &&
                std::abs(saved.sigma_hat - options.sigma_hat) <= 1e-8 * options.sigma_hat &&
                saved.method == options.reference_colors,
            path,
            "was made with colour space " + ColorSpaceName(saved.color_space) + ", sigma_hat " +
                std::to_string(saved.sigma_hat) + " and method " + EnumToString(saved.method) +
                ", but the config asks for " + ColorSpaceName(options.image.color_space) + ", " +
                std::to_string(options.sigma_hat) + " and " +
                EnumToString(options.reference_colors) + ": use another output folder");
    return saved;
  }
  Require(config.reference_frame < capture->num_frames(), "model.reference_frame",
          "frame " + std::to_string(config.reference_frame) + " does not exist in " +
              capture->directory());
  FrameInput reference = ReadFrameInput(capture, config.reference_frame,
                                        config.capture.skip_unreadable_cameras, nullptr);
  TakeHeldOutViews(config, &reference);  // Held-out cameras colour nothing.
  WriteReferenceColors(path, ComputeSequenceColors(model, reference, config.refine));
  // As saved: every run and shard on this folder then starts from the very same colours.
  return ReadReferenceColors(path, model.num_fine_vertices());
}

Eigen::VectorXd TrueFineDisplacement(const Capture& capture, const SequenceModel& model,
                                     const Mesh& coarse, int frame) {
  if (!capture.HasTrueSurface(frame)) return {};
  const Mesh fine = model.Subdivide(coarse);
  return TrueDisplacementAlongNormals(fine.vertices, ComputeVertexNormals(fine),
                                      capture.ReadTrueSurface(frame), 0.1);
}

std::vector<RefinedFrame> FindRefinedFrames(const Config& config, const Capture& capture,
                                            const std::string& out) {
  const FrameRange range = internal::ConfiguredFrames(config, capture);
  std::vector<RefinedFrame> frames;
  for (int frame = range.begin; frame < range.end; ++frame) {
    const std::string& name = capture.frame_name(frame);
    const FrameFiles files = FrameFilesIn(out, name, config.output.mesh_format);
    if (FrameDone(files)) frames.push_back({frame, name, files.mesh, files.displacement});
  }
  Require(!frames.empty(), out,
          "holds no refined run of the configured frames of " + capture.directory() +
              " (no meshes/<frame>." + config.output.mesh_format +
              " with k/<frame>.txt and frames/<frame>.json): run finecap refine first");
  return frames;
}

// A k/<frame>.txt file: one number (or nan) per fine vertex, '#' lines are comments.
Eigen::VectorXd ReadDisplacement(const std::string& path, int num_vertices) {
  std::istringstream text(internal::ReadWholeFile(path));
  std::vector<double> values;
  std::string line;
  for (int line_number = 1; std::getline(text, line); ++line_number) {
    if (line.empty() || line[0] == '#') continue;
    double value = 0.0;
    Require(
        internal::ParseDouble(line, &value) && !std::isinf(value), path,
        "line " + std::to_string(line_number) + ": expected a number or nan, got '" + line + "'");
    values.push_back(value);
  }
  Require(static_cast<int>(values.size()) == num_vertices, path,
          "holds " + std::to_string(values.size()) + " displacements, the refined mesh has " +
              std::to_string(num_vertices) + " vertices");
  return Eigen::Map<const Eigen::VectorXd>(values.data(), values.size());
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
