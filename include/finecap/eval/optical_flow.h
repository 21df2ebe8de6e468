// Dense optical flow between two images, and the mean length of its vectors over a mask: the
// measure behind the paper's flow evaluation (section 7), which needs no ground truth.
//
// Conventions: a flow field is CV_32FC2 of the size of the first image; the vector at pixel
// (x, y) is (dx, dy) in pixels such that pixel (x, y) of `from` is seen at (x + dx, y + dy) in
// `to` (OpenCV's convention). Colour images are compared as their grey levels, which is what
// both methods work on.
#ifndef FINECAP_EVAL_OPTICAL_FLOW_H_
#define FINECAP_EVAL_OPTICAL_FLOW_H_

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "finecap/util/enum_names.h"

namespace finecap {

// kDis ("dis"): OpenCV's Dense Inverse Search (Kroeger et al. 2016), fast; kDeepFlow
// ("deepflow"): DeepFlow (Weinzaepfel et al. 2013, opencv_contrib's optflow module), slower
// (seconds per megapixel) but closer to the variational flow of the paper's time.
enum class FlowMethod { kDis, kDeepFlow };
const std::vector<EnumName<FlowMethod>>& EnumNames(FlowMethod);

// OpenCV's presets of DIS, "ultrafast", "fast" and "medium": coarser patches and fewer
// iterations are faster and less precise.
enum class DisPreset { kUltrafast, kFast, kMedium };
const std::vector<EnumName<DisPreset>>& EnumNames(DisPreset);

struct OpticalFlowOptions {
  // Default kDis.
  FlowMethod method = FlowMethod::kDis;
  // DIS only. Default kMedium.
  DisPreset dis_preset = DisPreset::kMedium;

  // Throws Error naming the field when a value is not one of those above.
  void Check() const;
};

// The flow from `from` to `to`, two images of the same size, each 8-bit with 1 or 3 (BGR)
// channels. Throws Error(where, ...) when the images are empty, differ in size or are of another
// type, or when the options are invalid.
cv::Mat ComputeOpticalFlow(const cv::Mat& from, const cv::Mat& to,
                           const OpticalFlowOptions& options, const std::string& where);

// Sum of the lengths of the flow vectors at the non-zero pixels of `mask` (CV_8U, same size as
// `flow`) and how many there were; non-finite vectors are skipped. Sums of several images or
// frames add up to a pooled mean. Throws Error(where, ...) on a type or size mismatch.
struct FlowMagnitudeSum {
  double sum_px = 0.0;
  long count = 0;

  void Add(const FlowMagnitudeSum& other) {
    sum_px += other.sum_px;
    count += other.count;
  }
  // Mean length in pixels; NaN when no pixel counted.
  double mean_px() const;
};
FlowMagnitudeSum SumFlowMagnitude(const cv::Mat& flow, const cv::Mat& mask,
                                  const std::string& where);

}  // namespace finecap

#endif  // FINECAP_EVAL_OPTICAL_FLOW_H_
