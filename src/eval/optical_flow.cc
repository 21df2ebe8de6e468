#include "finecap/eval/optical_flow.h"

#include <cmath>
#include <limits>

#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "finecap/util/error.h"
#include "util/opencv_extras.h"
#include "util/option_checks.h"

namespace finecap {

const std::vector<EnumName<FlowMethod>>& EnumNames(FlowMethod) {
  static const std::vector<EnumName<FlowMethod>> names = {{FlowMethod::kDis, "dis"},
                                                          {FlowMethod::kDeepFlow, "deepflow"}};
  return names;
}

const std::vector<EnumName<DisPreset>>& EnumNames(DisPreset) {
  static const std::vector<EnumName<DisPreset>> names = {{DisPreset::kUltrafast, "ultrafast"},
                                                         {DisPreset::kFast, "fast"},
                                                         {DisPreset::kMedium, "medium"}};
  return names;
}

namespace {

int OpenCvPreset(DisPreset preset) {
  if (preset == DisPreset::kUltrafast) return cv::DISOpticalFlow::PRESET_ULTRAFAST;
  if (preset == DisPreset::kFast) return cv::DISOpticalFlow::PRESET_FAST;
  return cv::DISOpticalFlow::PRESET_MEDIUM;
}

// Both methods take single-channel 8-bit images.
cv::Mat Grey(const cv::Mat& image) {
  if (image.channels() == 1) return image;
  cv::Mat grey;
  cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  return grey;
}

void RequireFlowImage(const cv::Mat& image, const std::string& where, const std::string& which) {
  Require(!image.empty(), where, which + " image is empty");
  Require(image.type() == CV_8UC1 || image.type() == CV_8UC3, where,
          which + " image must be 8-bit with 1 or 3 channels");
}

}  // namespace

void OpticalFlowOptions::Check() const {
  internal::RequireKnownChoice(method, "OpticalFlowOptions::method");
  internal::RequireKnownChoice(dis_preset, "OpticalFlowOptions::dis_preset");
}

cv::Mat ComputeOpticalFlow(const cv::Mat& from, const cv::Mat& to,
                           const OpticalFlowOptions& options, const std::string& where) {
  options.Check();
  RequireFlowImage(from, where, "the first");
  RequireFlowImage(to, where, "the second");
  Require(from.size() == to.size(), where, "the two images differ in size");
  if (options.method == FlowMethod::kDeepFlow) {
    return internal::LoadOpenCvExtras("optical flow by DeepFlow").deep_flow(Grey(from), Grey(to));
  }
  cv::Mat flow;
  cv::DISOpticalFlow::create(OpenCvPreset(options.dis_preset))->calc(Grey(from), Grey(to), flow);
  return flow;
}

double FlowMagnitudeSum::mean_px() const {
  return count > 0 ? sum_px / count : std::numeric_limits<double>::quiet_NaN();
}

FlowMagnitudeSum SumFlowMagnitude(const cv::Mat& flow, const cv::Mat& mask,
                                  const std::string& where) {
  Require(flow.type() == CV_32FC2, where, "a flow field must be CV_32FC2");
  Require(mask.type() == CV_8UC1 && mask.size() == flow.size(), where,
          "the mask must be CV_8U and of the flow field's size");
  FlowMagnitudeSum total;
  for (int y = 0; y < flow.rows; ++y) {
    const cv::Vec2f* vectors = flow.ptr<cv::Vec2f>(y);
    const unsigned char* inside = mask.ptr<unsigned char>(y);
    for (int x = 0; x < flow.cols; ++x) {
      const double length = std::hypot(vectors[x][0], vectors[x][1]);
      if (!inside[x] || !std::isfinite(length)) continue;
      total.sum_px += length;
      ++total.count;
    }
  }
  return total;
}

}  // namespace finecap
