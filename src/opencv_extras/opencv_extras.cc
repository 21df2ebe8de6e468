// libfinecap_opencv_extras.so: the OpenCV modules that finecap loads only on use (see
// src/util/opencv_extras.h), behind the table that header declares.
#include "util/opencv_extras.h"

#include <opencv2/optflow.hpp>
#include <opencv2/videoio.hpp>

namespace finecap {
namespace internal {
namespace {

class OpenCvVideoReader : public VideoReader {
 public:
  bool Open(const std::string& path) { return capture_.open(path); }

  bool Read(cv::Mat* image) override { return capture_.read(*image); }
  bool Grab() override { return capture_.grab(); }
  void Seek(int frame) override { capture_.set(cv::CAP_PROP_POS_FRAMES, frame); }

 private:
  cv::VideoCapture capture_;
};

std::unique_ptr<VideoReader> OpenVideo(const std::string& path) {
  auto reader = std::make_unique<OpenCvVideoReader>();
  if (!reader->Open(path)) return nullptr;
  return reader;
}

cv::Mat DeepFlow(const cv::Mat& from, const cv::Mat& to) {
  cv::Mat flow;
  cv::optflow::createOptFlow_DeepFlow()->calc(from, to, flow);
  return flow;
}

}  // namespace
}  // namespace internal
}  // namespace finecap

extern "C" __attribute__((visibility("default"))) const finecap::internal::OpenCvExtras*
finecap_opencv_extras_v1() {
  static const finecap::internal::OpenCvExtras table = {finecap::internal::OpenVideo,
                                                        finecap::internal::DeepFlow};
  return &table;
}
