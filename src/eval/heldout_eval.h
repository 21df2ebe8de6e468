// What the evaluation of a run (run_evaluation.h) reports of the held-out cameras: figures per
// frame and pooled, pictures, their JSON and their report section.
#ifndef FINECAP_SRC_HELDOUT_EVAL_H_
#define FINECAP_SRC_HELDOUT_EVAL_H_

#include <string>
#include <utility>
#include <vector>

#include "finecap/eval/html_report.h"
#include "finecap/measure/heldout_score.h"
#include "finecap/refine/refine.h"

namespace finecap {
namespace internal {

// The surfaces of a held-out score, in order: the coarse mesh as given (the input its user gave),
// its subdivision (where refinement starts) and the refined mesh as written.
enum HeldOutSurface { kHeldOutCoarse = 0, kHeldOutSubdivided = 1, kHeldOutRefined = 2 };
constexpr int kNumHeldOutSurfaces = 3;

// The held-out score of one frame, its surfaces as HeldOutSurface numbers them.
struct HeldOutFrame {
  std::string frame;
  HeldOutScore score;
  // Per held-out view when kept (see EvaluateHeldOutFrame), else empty: the photo, what the input
  // as given and the refined mesh predict there, and their NCC maps, cut to the subject.
  std::vector<std::vector<ReportPanel>> panels;
  std::vector<std::string> captions;  // One per entry of `panels`.
};

// Scores `coarse` (the frame's coarse mesh as given), `input` (its subdivision) and `refined` in
// the views of `frame` named in `held_out_cameras` (training views: the rest of `frame`), writes
// one picture per held-out view (the input as given beside the refined mesh) to
// eval_dir/heldout_<frame>_<camera>.png and appends its path and caption to `*pictures`. With
// `keep_panels` the result also holds the pictures' parts, for the report's comparison panels.
HeldOutFrame EvaluateHeldOutFrame(const std::vector<std::string>& held_out_cameras,
                                  const HeldOutOptions& options, const std::string& frame_name,
                                  FrameInput frame, const Mesh& coarse, const Mesh& input,
                                  const Mesh& refined, const std::string& eval_dir,
                                  bool keep_panels,
                                  std::vector<std::pair<std::string, std::string>>* pictures);

// The means over every frame's held-out views, per surface (HeldOutSurface).
std::vector<SurfaceScore> PooledHeldOutScore(const std::vector<HeldOutFrame>& frames);

// JSON members for metrics.json: the pooled figures ("heldout_ncc_input", ...) and, per frame,
// a "heldout" object with the frame's means and its views.
std::string HeldOutPooledJson(const std::vector<HeldOutFrame>& frames, const std::string& indent);
std::string HeldOutFrameJson(const HeldOutFrame& frame);

// What the report's section of the held-out cameras holds: the table of figures (pooled, per frame
// and per view), then the comparison panels of the frames that kept them.
void AddHeldOutSection(const std::vector<HeldOutFrame>& frames, const HeldOutOptions& options,
                       HtmlReport* report);

}  // namespace internal
}  // namespace finecap

#endif  // FINECAP_SRC_HELDOUT_EVAL_H_
