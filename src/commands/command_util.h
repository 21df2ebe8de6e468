// What the subcommands share: opening the input capture, preparing the output folder, the
// library's options from the config, a sequence refined with its progress on the terminal.
#ifndef FINECAP_SRC_COMMANDS_COMMAND_UTIL_H_
#define FINECAP_SRC_COMMANDS_COMMAND_UTIL_H_

#include <chrono>
#include <string>
#include <vector>

#include "finecap/config/config.h"
#include "finecap/io/capture.h"
#include "finecap/measure/heldout_score.h"
#include "finecap/refine/refine.h"
#include "finecap/refine/run_folder.h"
#include "finecap/refine/sequence.h"
#include "refine/scene_scale.h"

namespace finecap {
namespace internal {

// Opens config.capture.dir; an Error names the key when it is empty, and names
// validation.cameras when one of its names is not a camera of the capture or when it holds out
// every camera.
Capture OpenConfiguredCapture(const Config& config);

// The configured frames of `capture`; an Error when the range holds none of its frames.
FrameRange ConfiguredFrames(const Config& config, const Capture& capture);

// config.output.dir as an absolute path, without creating it; refuses the capture folder itself
// or a folder inside it, so that nothing a user gave is ever written over.
std::string CheckOutputFolder(const Config& config, const Capture& capture);

// CheckOutputFolder, and creates the folder (and its parents) unless it exists.
std::string PrepareOutputFolder(const Config& config, const Capture& capture);

// output.dir of a previous `finecap refine`, which must exist (nothing is created).
std::string RefinedRunFolder(const Config& config);

// `config` with the lengths that follow from the scene chosen (ResolveSceneScaleDefaults on the
// configured reference frame), and a line on stderr, "finecap <command>: scene length ...", that
// says what they are and from what. Then checks that the mesh's size fits sigma_hat (metres, not
// millimetres: RequirePlausibleSceneScale), against the person-sized 7 mm when sigma_hat follows
// from the scene. `defaults` (may be null) receives what was measured and chosen.
Config WithSceneLengths(const Config& config, const Capture& capture, const std::string& command,
                        SceneScaleDefaults* defaults = nullptr);

// Below this share of vertices refined with confidence (or, before a run, of vertices that its
// cameras alone let be: ProblemSize::num_well_seen_refined_vertices) a capture cannot be refined
// usefully: most of the surface then stays near the input, for want of views.
constexpr double kUsefulConfidentShare = 0.5;
// Why a capture with only `share` of its surface refined with confidence is not refined usefully:
// "only N % of its surface is seen well enough ...", naming the keys that decide it.
std::string TooFewViewsReason(double share);

// A count for people: "8100", "1.2 M", "85 M".
std::string RoundedCount(double count);
// A duration for people: "0.8 s", "12 s", "3.5 min".
std::string RoundedSeconds(double seconds);
// " (up to N MB if a frame's plane sweep widens its search range to R)" where the sweep may widen
// a frame's range beyond the configured one (ProblemSize::widest_k_max); empty where it may not.
std::string WidestRangeForecast(const ProblemSize& size);

// What the library's sequence and run folder take from the config.
SequenceOptions SequenceOptionsOf(const Config& config);
MeshFormat MeshFormatOf(const Config& config);

// The reference colours of the run folder `out` (LoadOrComputeReferenceColors), with a warning on
// stderr for each camera skipped in the reference frame.
ReferenceColors ConfiguredReferenceColors(const Config& config, const SequenceModel& model,
                                          Capture* capture, const std::string& out);

// Refines `frames` of `capture` into `out` (RefineSequence) as `finecap <command>` shows it: the
// problem size first, then a progress line per frame and warnings on stderr; then where the
// results are and, with ground truth, the error over the frames refined now on stdout.
void RefineConfiguredSequence(const Config& config, const FrameRange& frames,
                              const std::string& out, const std::string& command, Capture* capture);

// The configured frames done in the run folder `out`, in frame order; an Error naming `out` when
// there is none.
std::vector<RefinedFrame> FindRefinedFrames(const Config& config, const Capture& capture,
                                            const std::string& out);

// Progress of a run over frames: a line rewritten in place on a terminal, plain lines otherwise.
class Progress {
 public:
  explicit Progress(int total);
  // Call after each frame; `skipped` frames do not count towards the time per frame.
  void FrameDone(const std::string& name, bool skipped, const std::string& detail);

 private:
  int total_;
  int done_ = 0;
  int timed_ = 0;
  double seconds_ = 0.0;
  bool terminal_;
  std::chrono::steady_clock::time_point last_;
};

}  // namespace internal
}  // namespace finecap

#endif  // FINECAP_SRC_COMMANDS_COMMAND_UTIL_H_
