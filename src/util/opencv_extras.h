// Video input and DeepFlow, the two parts of OpenCV that finecap rarely needs, live in a shared
// library of their own, libfinecap_opencv_extras.so, loaded on first use (not part of the public
// API). Linked into finecap they would cost every start ~240 shared libraries (opencv_videoio
// with GStreamer and FFmpeg; opencv_optflow with ximgproc and imgcodecs, which bring GDAL): a
// third of a second and ~70 MB before any work, for captures that are image folders and
// evaluations that use DIS.
//
// The library is looked for next to the running executable (/proc/self/exe's folder), then at the
// path the build put it (for executables built elsewhere in the build tree). It is built with the
// same compiler and OpenCV as finecap, so its interface is plain C++ (cv::Mat and std::string),
// reached through one extern "C" function that returns the table below.
#ifndef FINECAP_SRC_UTIL_OPENCV_EXTRAS_H_
#define FINECAP_SRC_UTIL_OPENCV_EXTRAS_H_

#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace finecap {
namespace internal {

// A video opened with cv::VideoCapture; frames come out as OpenCV gives them (8-bit BGR).
class VideoReader {
 public:
  virtual ~VideoReader() = default;

  // The next frame into `image`; false at the end of the video or when it cannot be decoded.
  virtual bool Read(cv::Mat* image) = 0;

  // Steps over the next frame without converting it; false at the end of the video.
  virtual bool Grab() = 0;

  // Makes `frame` the next frame read (CAP_PROP_POS_FRAMES; exact or not, as the codec allows).
  virtual void Seek(int frame) = 0;
};

struct OpenCvExtras {
  // The video at `path`, or nullptr when cv::VideoCapture cannot open it.
  std::unique_ptr<VideoReader> (*open_video)(const std::string& path);

  // DeepFlow (opencv_contrib's optflow) from `from` to `to`, both CV_8UC1 of one size: CV_32FC2.
  cv::Mat (*deep_flow)(const cv::Mat& from, const cv::Mat& to);
};

// The library's table, loaded from OpenCvExtrasCandidates() on the first call (thread-safe) and
// kept for the process's life. Throws Error naming the library, `needed_for` ("video input
// (videos/cam0.mp4)") and why each candidate failed when it cannot be loaded.
const OpenCvExtras& LoadOpenCvExtras(const std::string& needed_for);

// Where the library is looked for, in order: beside the running executable, then where the build
// put it.
std::vector<std::string> OpenCvExtrasCandidates();

// As LoadOpenCvExtras from the first of `candidates` that loads, without keeping the outcome.
const OpenCvExtras& LoadOpenCvExtrasFrom(const std::vector<std::string>& candidates,
                                         const std::string& needed_for);

}  // namespace internal
}  // namespace finecap

// The one symbol the library exports; its name carries the table's version, so that a stale
// library is refused by name rather than called with the wrong layout.
#define FINECAP_OPENCV_EXTRAS_SYMBOL "finecap_opencv_extras_v1"
extern "C" const finecap::internal::OpenCvExtras* finecap_opencv_extras_v1();

#endif  // FINECAP_SRC_UTIL_OPENCV_EXTRAS_H_
