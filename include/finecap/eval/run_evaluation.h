// A refined run folder (run_folder.h) measured: against the capture's ground truth when it has
// one (evaluation.h), by optical flow to the images (flow_evaluation.h) and in the held-out
// cameras (heldout_score.h). EvaluateRun writes its pictures, plots, metrics.json, flow.csv and
// report.html into one folder, the run folder's eval/, and prints nothing: what a user should see
// goes to an EvaluationObserver and into the RunEvaluation it returns.
#ifndef FINECAP_EVAL_RUN_EVALUATION_H_
#define FINECAP_EVAL_RUN_EVALUATION_H_

#include <optional>
#include <string>
#include <vector>

#include "finecap/eval/evaluation.h"
#include "finecap/eval/flow_evaluation.h"
#include "finecap/eval/optical_flow.h"
#include "finecap/io/capture.h"
#include "finecap/measure/heldout_score.h"
#include "finecap/refine/refine.h"
#include "finecap/refine/run_folder.h"
#include "finecap/util/option_fields.h"

namespace finecap {

struct RunEvaluationOptions {
  // What the run was refined with: its subdivision fixes the fine mesh, its visibility the
  // texture the flow renders; its lengths should be resolved as they were (scene_scale.h).
  RefineOptions refine;
  // The frame whose images texture the model the flow renders; its range is
  // SequenceOptions::reference_frame's.
  int reference_frame = 0;
  // An index into the capture's cameras, documented where Fields() declares it
  // (docs/configuration.md: eval.camera).
  int camera = 0;
  // Measure the optical-flow figures; without, they are NaN (null in metrics.json). Default true.
  bool measure_flow = true;
  OpticalFlowOptions flow;
  // The flow in every camera, their pixels pooled (default), or only in `camera`.
  bool flow_in_all_cameras = true;
  // The cameras the run held out (SequenceOptions::held_out_cameras): scored per frame, with
  // pictures. Default none.
  std::vector<std::string> held_out_cameras;
  HeldOutOptions held_out_score;

  static const OptionFields<RunEvaluationOptions>& Fields();  // option_fields.h
  void Check() const;
};

// Which surface of the reference frame textured the refined mesh for the optical flow
// (flow_evaluation.h): its own, the refined reference mesh, or (when the run folder holds no
// refined reference frame) the subdivided input mesh, whose texture then paints both meshes.
enum class RefinedFlowTexture { kRefinedReferenceMesh, kInputReferenceMesh };

// "refined_reference_mesh" or "input_reference_mesh", as metrics.json names them.
const char* RefinedFlowTextureName(RefinedFlowTexture texture);

// What EvaluateRun tells its caller while it runs; every method does nothing unless overridden.
class EvaluationObserver {
 public:
  virtual ~EvaluationObserver() = default;
  virtual void FrameEvaluated(const std::string& /*frame*/) {}
  // three.js was not found (mesh_viewer.h): the report has a note in place of its 3D view.
  virtual void ViewerUnavailable() {}
  // The reference frame `frame` is not refined in the run folder: the flow paints the refined
  // mesh with the input's texture (RefinedFlowTexture::kInputReferenceMesh). Called once.
  virtual void RefinedReferenceUnavailable(const std::string& /*frame*/) {}
};

// The headline figures of an evaluated run, and where its files are.
struct RunEvaluation {
  EvaluationFigures sequence;  // Every frame's vertices pooled.
  bool flow_measured = false;
  // What textured the refined mesh for the flow, when measured.
  RefinedFlowTexture refined_flow_texture = RefinedFlowTexture::kInputReferenceMesh;
  FlowComparison flow;  // Pooled over the frames and cameras.
  // In the held-out cameras, pooled: the coarse mesh as given (the input), its subdivision and
  // the refined mesh, in that order; empty without held-out cameras.
  std::vector<SurfaceScore> heldout;
  std::string report, metrics;  // report.html and metrics.json.
};

// Evaluates `frames` of `capture` (the done frames of a run folder: FindRefinedFrames) into
// `folder` (created when missing; EvalFolder of the run folder). `refined_reference` is the run
// folder's reference frame (options.reference_frame) when it is done there (FindRefinedFrame),
// whether or not it is among `frames`: its refined mesh textures the refined mesh for the flow;
// without it the input's texture paints both and the observer hears of it. Throws Error naming
// the file or the option when an input cannot be read or `options` are invalid (Check()).
// `observer` may be null.
RunEvaluation EvaluateRun(Capture* capture, const std::vector<RefinedFrame>& frames,
                          const std::optional<RefinedFrame>& refined_reference,
                          const RunEvaluationOptions& options, const std::string& folder,
                          EvaluationObserver* observer = nullptr);

}  // namespace finecap

#endif  // FINECAP_EVAL_RUN_EVALUATION_H_
