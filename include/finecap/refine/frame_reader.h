// Reading one frame of a capture as refinement sees it: the coarse mesh and every camera's image,
// decoded and undistorted (capture.h), with the held-out cameras set aside; and a reader that
// reads the next frame on a thread of its own while the current one is solved.
#ifndef FINECAP_REFINE_FRAME_READER_H_
#define FINECAP_REFINE_FRAME_READER_H_

#include <condition_variable>
#include <deque>
#include <functional>
#include <future>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "finecap/io/capture.h"
#include "finecap/measure/heldout_score.h"
#include "finecap/refine/refine.h"

namespace finecap {

// A camera left out of a frame because its image could not be read, and why.
struct SkippedCamera {
  std::string camera;
  std::string error;  // The Error's message.
};

// The coarse mesh, cameras and undistorted images of `frame`, and their masks when the capture
// has masks; a camera's unreadable image or mask throws its Error.
FrameInput ReadFrameInput(Capture* capture, int frame);

// The same, except that with `skip_unreadable` a camera whose image cannot be read is left out of
// the frame and appended to `*skipped` (which may be null otherwise). When no camera's image can
// be read, the first camera's error is thrown.
FrameInput ReadFrameInput(Capture* capture, int frame, bool skip_unreadable,
                          std::vector<SkippedCamera>* skipped);

// Removes the cameras named in `held_out` and their images (and masks) from `input` and returns
// them, in the
// rig's order: what is left is all that refinement may see. Throws Error when no other camera is
// left (the others' images could not be read). Names that are no camera of `input` are ignored.
std::vector<CalibratedImage> TakeHeldOutViews(const std::vector<std::string>& held_out,
                                              FrameInput* input);

// The cameras, images and masks of `input`, for the held-out score.
std::vector<CalibratedImage> CalibratedImagesOf(const FrameInput& input);

// Reads frames as refinement sees them (ReadFrameInput with `skip_unreadable`, the cameras named
// in `held_out` set aside, and, given `image_options`, the images modelled) ahead on a thread of
// their own, so that reading and modelling the next frames overlap solving this one; and, given
// `work_ahead`, does that work on each frame read as well (a sequence prepares the frame's energy
// there: PrepareFrameAhead). Reads asked for ahead run one after another, in the order asked for,
// so that the work ahead takes one thread and its OpenMP team however far it reads. Only this
// reader may read from the capture while a read is under way. Memory grows with the frames read
// ahead and not yet taken (the caller bounds them) and the one kept.
class FrameReadAhead {
 public:
  struct Frame {
    FrameInput input;                       // Without the held-out cameras.
    std::vector<CalibratedImage> held_out;  // TakeHeldOutViews.
    std::vector<SkippedCamera> skipped;     // Cameras whose image could not be read.
    // Filled by `work_ahead`, when it does: the frame prepared for its solve (which takes the
    // input's image models, and may leave the input without its images when nothing else reads
    // them), and the ground truth at its fine vertices (a synthetic capture's).
    PreparedFrame prepared;
    FineGroundTruth truth;
  };
  // Work on frame `frame` once it is read, on the reader's thread (or the caller's, for a frame
  // Take reads itself), with as many OpenMP threads as the thread that made the reader had.
  using WorkAhead = std::function<void(int frame, Frame* read)>;

  FrameReadAhead(Capture* capture, bool skip_unreadable, std::vector<std::string> held_out,
                 std::optional<ImageGaussianOptions> image_options, WorkAhead work_ahead = {});
  // Waits for the reads under way (DropPending) and ends the reader's thread.
  ~FrameReadAhead();

  // Starts reading `frame` in the background once the reads asked for before it have ended,
  // unless it is kept or already asked for.
  void ReadAhead(int frame);

  // Frame `frame`: the one kept or read ahead when it is that frame (a read's errors are thrown
  // here), else read now.
  Frame Take(int frame);

  // Keeps `read`, frame `frame`, for the next Take of that frame: a frame used before the run
  // refines it (for the reference colours or the forecast) is not read and modelled again. A Take
  // of another frame drops it (a resumed run may never refine it).
  void Keep(int frame, Frame read);

  // Waits for the reads under way and drops them: before what `work_ahead` uses goes away.
  void DropPending();

  // Whether frames asked for ahead are still to be taken (their reads may have ended).
  bool ReadsAhead() const { return !pending_.empty(); }

 private:
  // `ahead`: read on the reader's thread, beside the work on the caller's; else on the caller's,
  // which waits for it.
  Frame Read(int frame, bool ahead);

  Capture* capture_;
  bool skip_unreadable_;
  std::vector<std::string> held_out_;
  std::optional<ImageGaussianOptions> image_options_;
  WorkAhead work_ahead_;
  // A frame asked for ahead.
  struct Pending {
    int frame = -1;
    std::future<Frame> read;
  };
  // Runs the reads ahead, in the order asked for, until the reader goes.
  void Work();

  int threads_;                  // OpenMP threads for the work ahead.
  std::deque<Pending> pending_;  // In the order asked for.
  // The reads ahead run on one thread for the reader's lifetime, started at the first: a thread
  // per read left memory behind in the libraries that keep state per thread (OpenCV's
  // thread-local data, ~0.8 KB a frame: bench/soak.sh), and started a new OpenMP team each time.
  std::thread thread_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::packaged_task<Frame()>> tasks_;  // Guarded by mutex_.
  bool ending_ = false;                            // Guarded by mutex_.
  int kept_frame_ = -1;
  Frame kept_;
};

}  // namespace finecap

#endif  // FINECAP_REFINE_FRAME_READER_H_
