// finecap eval: a refined run measured against the capture's ground truth (when it has one), by
// optical flow and in the held-out cameras; pictures, plots, metrics.json and report.html in
// output.dir/eval/ (run_evaluation.h).
#include <cmath>
#include <iostream>
#include <optional>

#include "commands/command_util.h"
#include "finecap/commands/commands.h"
#include "finecap/eval/run_evaluation.h"
#include "finecap/util/error.h"

namespace finecap {
namespace {

RunEvaluationOptions EvaluationOptionsOf(const Config& config) {
  RunEvaluationOptions options;
  options.refine = config.refine;
  options.reference_frame = config.reference_frame;
  options.camera = config.eval.camera;
  options.measure_flow = config.eval.flow != "none";
  // The schema allows only the tables' names here (and "none").
  if (options.measure_flow) StringToEnum(config.eval.flow, &options.flow.method);
  StringToEnum(config.eval.flow_dis_preset, &options.flow.dis_preset);
  options.flow_in_all_cameras = config.eval.flow_cameras == "all";
  options.held_out_cameras = config.validation.cameras;
  options.held_out_score = config.validation.score;
  return options;
}

// Evaluation's progress as `finecap eval` shows it.
class ConsoleObserver : public EvaluationObserver {
 public:
  explicit ConsoleObserver(int frames) : progress_(frames) {}
  void FrameEvaluated(const std::string& frame) override { progress_.FrameDone(frame, false, ""); }
  void ViewerUnavailable() override {
    std::cerr << "finecap eval: warning: three.js not found (install Debian's libjs-three or set "
                 "FINECAP_THREE_JS_DIR); report.html has a note in place of the 3D view\n";
  }
  void RefinedReferenceUnavailable(const std::string& frame) override {
    std::cerr << "finecap eval: warning: the reference frame " << frame
              << " is not refined in this run folder; the optical flow paints the refined mesh "
                 "with the input's texture (metrics.json: flow_refined_texture)\n";
  }

 private:
  internal::Progress progress_;
};

void PrintFigures(const RunEvaluation& evaluation) {
  const RegionFigures& all = evaluation.sequence.all;
  std::cout.precision(3);
  std::cout << "Evaluation: " << evaluation.report << ", " << evaluation.metrics << "\n";
  if (std::isfinite(all.coarse.rms)) {
    std::cout << "RMS against the ground truth: input as given " << 1000.0 * all.coarse.rms
              << " mm (subdivided " << 1000.0 * all.subdivided.rms << " mm), refined "
              << 1000.0 * all.refined.rms << " mm; detail recovered "
              << 100.0 * all.detail_recovered << " %; normal error " << all.normal_error_coarse_deg
              << " (subdivided " << all.normal_error_subdivided_deg << ") -> "
              << all.normal_error_refined_deg << " degrees\n";
  }
  if (std::isfinite(all.flicker.refined.rms)) {
    std::cout << "Flicker (RMS change of the signed error from one frame to the next): input as "
              << "given " << 1000.0 * all.flicker.coarse.rms << " mm (subdivided "
              << 1000.0 * all.flicker.subdivided.rms << " mm), refined "
              << 1000.0 * all.flicker.refined.rms << " mm, "
              << all.flicker.refined.rms / all.refined.rms << " of the refined error\n";
  }
  if (!evaluation.heldout.empty()) {
    // The input as given, its subdivision, the refined mesh.
    const std::vector<SurfaceScore>& pooled = evaluation.heldout;
    std::cout << "Held-out cameras: NCC input as given " << pooled[0].ncc << " (subdivided "
              << pooled[1].ncc << "), refined " << pooled[2].ncc << "; MAD input as given "
              << pooled[0].mad << " (subdivided " << pooled[1].mad << "), refined " << pooled[2].mad
              << " grey levels\n";
  }
  if (evaluation.flow_measured) {
    std::cout << "Optical flow to the images: input " << evaluation.flow.coarse.mean_px()
              << " px, refined " << evaluation.flow.refined.mean_px() << " px; improvement "
              << evaluation.flow.improvement_percent() << " %\n";
  }
}

}  // namespace

int RunEval(const Config& configured) {
  Capture capture = internal::OpenConfiguredCapture(configured);
  const Config config = internal::WithSceneLengths(configured, capture, "eval");
  const std::string out = internal::RefinedRunFolder(config);
  Require(config.eval.camera < capture.num_cameras(), "eval.camera",
          std::to_string(config.eval.camera) + " is not a camera of " + capture.directory() +
              ", which has " + std::to_string(capture.num_cameras()));
  const std::vector<RefinedFrame> frames = internal::FindRefinedFrames(config, capture, out);
  const std::optional<RefinedFrame> reference = FindRefinedFrame(
      out, capture.frame_names(), config.reference_frame, internal::MeshFormatOf(config));
  ConsoleObserver observer(frames.size());
  PrintFigures(EvaluateRun(&capture, frames, reference, EvaluationOptionsOf(config),
                           EvalFolder(out), &observer));
  return 0;
}

}  // namespace finecap
