// The images of one camera, delivered one frame at a time and undistorted on load.
//
// A FrameSource holds no more than one frame (and, for a lens with distortion, the camera's two
// undistortion maps) whatever the sequence's length. Every image it returns is CV_8UC3 BGR, of the
// camera's size, and undistorted: it is the image of `camera.Undistorted()` (same K, distortion
// zero), resampled bilinearly with maps computed once by cv::initUndistortRectifyMap.
#ifndef FINECAP_FRAME_SOURCE_H_
#define FINECAP_FRAME_SOURCE_H_

#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "finecap/geometry/camera.h"

namespace finecap {

class FrameSource {
 public:
  virtual ~FrameSource() = default;

  // The undistorted image of frame `frame`, 0 <= frame < num_frames(). Throws Error naming the
  // file when the image is missing, empty (0 bytes), truncated or undecodable, when its size is
  // not the camera's, or when a video ends before `frame`.
  virtual cv::Mat Read(int frame) = 0;

  virtual int num_frames() const = 0;
};

// Frame i is the image `folder`/<frame_names[i]>.png (or .jpg, .jpeg; extension case ignored),
// read as its pixels are stored (an EXIF orientation tag is ignored: the camera is calibrated on
// those pixels).
// When no file has exactly that stem and the frame name is a number, an image whose stem is the
// same number (`12.png` for frame `000012`) is taken. The folder is listed once, here; a frame
// without an image is reported when it is read.
std::unique_ptr<FrameSource> MakeImageFolderSource(const std::string& folder,
                                                   const std::vector<std::string>& frame_names,
                                                   const Camera& camera);

// The foreground masks of one camera, found as MakeImageFolderSource finds images: Read returns
// CV_8UC1, 255 on the foreground and 0 on the background, of the camera's size and undistorted
// like its images but by the nearest pixel (a mask's values are labels, not to be blended). A PNG
// pixel is foreground when any of its channels is non-zero; a JPEG's (whose compression leaves
// faint values in the background) when one is above 127. Read throws Error naming the file when
// it is missing, unreadable, or not of the camera's size.
std::unique_ptr<FrameSource> MakeMaskFolderSource(const std::string& folder,
                                                  const std::vector<std::string>& frame_names,
                                                  const Camera& camera);

// The mask file at `path` as the one frame, read as MakeMaskFolderSource reads each: COLMAP's
// masks/NAME.png of its flat images/NAME layout.
std::unique_ptr<FrameSource> MakeMaskFileSource(const std::string& path, const Camera& camera);

// Frame i is the i-th frame of the video at `path` (anything cv::VideoCapture opens), for
// `num_frames` frames. OpenCV's video input is loaded here, on the first video opened, from
// libfinecap_opencv_extras.so; Error names that library when it cannot be loaded. Frames asked in
// increasing order are decoded sequentially (skipping forward up to 32 frames by decoding them);
// any other jump seeks with CAP_PROP_POS_FRAMES.
std::unique_ptr<FrameSource> MakeVideoSource(const std::string& path, int num_frames,
                                             const Camera& camera);

// MakeImageFolderSource when `path` is a folder; the image itself, as the one frame, when it is
// an image file (.png, .jpg, .jpeg, case ignored; COLMAP's flat layout); else MakeVideoSource
// with frame_names.size(). The camera must have a positive size (Camera::Validate); throws Error
// naming `path` otherwise, when it does not exist, or when an image file is asked for more than
// one frame.
std::unique_ptr<FrameSource> OpenFrameSource(const std::string& path,
                                             const std::vector<std::string>& frame_names,
                                             const Camera& camera);

// The size of frame 0 as stored at `path` (a folder or a video, as for OpenFrameSource), for rigs
// that do not state their image size. Throws Error naming the file when it cannot be read.
cv::Size ReadFirstFrameSize(const std::string& path, const std::vector<std::string>& frame_names);

}  // namespace finecap

#endif  // FINECAP_FRAME_SOURCE_H_
