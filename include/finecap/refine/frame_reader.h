// Reading one frame of a capture as refinement sees it: the coarse mesh and every camera's image,
// decoded and undistorted (capture.h), with the held-out cameras set aside; and a reader that
// reads the next frame on a thread of its own while the current one is solved.
#ifndef FINECAP_REFINE_FRAME_READER_H_
#define FINECAP_REFINE_FRAME_READER_H_

#include <future>
#include <string>
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

// The coarse mesh, cameras and undistorted images of `frame`; a camera's unreadable image throws
// its Error.
FrameInput ReadFrameInput(Capture* capture, int frame);

// The same, except that with `skip_unreadable` a camera whose image cannot be read is left out of
// the frame and appended to `*skipped` (which may be null otherwise). When no camera's image can
// be read, the first camera's error is thrown.
FrameInput ReadFrameInput(Capture* capture, int frame, bool skip_unreadable,
                          std::vector<SkippedCamera>* skipped);

// Removes the cameras named in `held_out` and their images from `input` and returns them, in the
// rig's order: what is left is all that refinement may see. Throws Error when no other camera is
// left (the others' images could not be read). Names that are no camera of `input` are ignored.
std::vector<CalibratedImage> TakeHeldOutViews(const std::vector<std::string>& held_out,
                                              FrameInput* input);

// The cameras and images of `input`, for the held-out score.
std::vector<CalibratedImage> CalibratedImagesOf(const FrameInput& input);

// Reads frames (ReadFrameInput with `skip_unreadable`) one frame ahead on a thread of its own, so
// that reading the next frame overlaps solving this one and both cores stay busy. Only this reader
// may read images from the capture while a read is under way; at most one frame is read ahead
// (bounded memory).
class FrameReadAhead {
 public:
  FrameReadAhead(Capture* capture, bool skip_unreadable);

  // Starts reading `frame` in the background, unless a read is already under way.
  void ReadAhead(int frame);

  // The input of `frame`: the one read ahead when it is that frame (its errors are thrown here),
  // else read now. The cameras skipped go to *skipped.
  FrameInput Take(int frame, std::vector<SkippedCamera>* skipped);

 private:
  struct Frame {
    FrameInput input;
    std::vector<SkippedCamera> skipped;
  };
  Frame Read(int frame);

  Capture* capture_;
  bool skip_unreadable_;
  int pending_frame_ = -1;
  std::future<Frame> pending_;
};

}  // namespace finecap

#endif  // FINECAP_REFINE_FRAME_READER_H_
