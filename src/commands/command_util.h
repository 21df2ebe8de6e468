// What the subcommands share: opening the input capture, preparing the output folder, reading
// one frame, the reference colours, and progress output.
#ifndef FINECAP_SRC_COMMANDS_COMMAND_UTIL_H_
#define FINECAP_SRC_COMMANDS_COMMAND_UTIL_H_

#include <chrono>
#include <string>
#include <vector>

#include "finecap/capture.h"
#include "finecap/config.h"
#include "finecap/heldout_score.h"
#include "finecap/refine.h"
#include "finecap/scene_scale.h"

namespace finecap {
namespace internal {

// Opens config.capture.dir; an Error names the key when it is empty, and names
// validation.cameras when one of its names is not a camera of the capture or when it holds out
// every camera.
Capture OpenConfiguredCapture(const Config& config);

// Removes the held-out cameras (validation.cameras) and their images from `input` and returns
// them, in the rig's order: what is left is all that refinement may see. Throws Error when no
// other camera is left (the others' images could not be read).
std::vector<CalibratedImage> TakeHeldOutViews(const Config& config, FrameInput* input);

// The cameras and images of `input`, for the held-out score.
std::vector<CalibratedImage> CalibratedImagesOf(const FrameInput& input);

// The configured frames of `capture`; an Error when the range holds none of its frames.
FrameRange ConfiguredFrames(const Config& config, const Capture& capture);

// Creates config.output.dir (and its parents) unless it exists; refuses the capture folder
// itself or a folder inside it, so that nothing a user gave is ever written over.
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

// A count for people: "8100", "1.2 M", "85 M".
std::string RoundedCount(double count);
// A duration for people: "0.8 s", "12 s", "3.5 min".
std::string RoundedSeconds(double seconds);

// The coarse mesh, cameras and undistorted images of one frame.
FrameInput ReadFrameInput(Capture* capture, int frame);

// The same, except that with `skip_unreadable` a camera whose image cannot be read is left out of
// the frame (with a warning on stderr) and its name appended to `*skipped` (which may be null
// otherwise). When no camera's image can be read, the first camera's error is thrown.
FrameInput ReadFrameInput(Capture* capture, int frame, bool skip_unreadable,
                          std::vector<std::string>* skipped);

// The reference colours saved in `path`, or, when there is no such file, those of the
// configured reference frame, computed, saved there and read back (so a run uses exactly what a
// later resumed run or shard will read).
ReferenceColors LoadOrComputeReferenceColors(const Config& config, const SequenceModel& model,
                                             Capture* capture, const std::string& path);

// The true displacement of every fine vertex along its normal (NaN where unknown), or an empty
// vector when the capture has no true surface for the frame.
Eigen::VectorXd TrueFineDisplacement(const Capture& capture, const SequenceModel& model,
                                     const Mesh& coarse, int frame);

// The files `finecap refine` wrote for one frame.
struct RefinedFrame {
  int index = 0;
  std::string name, mesh, displacement;
};

// The configured frames done in `out` (mesh, displacement and stats record), in frame order;
// an Error naming `out` when there is none.
std::vector<RefinedFrame> FindRefinedFrames(const Config& config, const Capture& capture,
                                            const std::string& out);

// A k/<frame>.txt file: one number (or nan) per vertex of the refined mesh.
Eigen::VectorXd ReadDisplacement(const std::string& path, int num_vertices);

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
