#include "refine/foreground.h"

#include <cmath>

#include <opencv2/imgproc.hpp>

#include "finecap/util/error.h"

namespace finecap {

void KeepForeground(const Camera& camera, const cv::Mat& mask, const Eigen::Matrix3Xd& points,
                    int margin, std::vector<unsigned char>* visible) {
  Require(mask.type() == CV_8UC1 && mask.cols == camera.width && mask.rows == camera.height,
          camera.name, "the mask must be CV_8UC1 of the camera's size");
  Require(visible->size() == static_cast<size_t>(points.cols()), camera.name,
          "one visibility flag per point expected");
  cv::Mat foreground;  // A buffer of its own: eroding into `mask`'s would change the caller's.
  if (margin > 0) {
    // Beyond the image counts as background too: a read there is clamped to the border.
    cv::erode(mask, foreground,
              cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * margin + 1, 2 * margin + 1)),
              cv::Point(-1, -1), 1, cv::BORDER_CONSTANT, cv::Scalar(0));
  } else {
    foreground = mask;
  }
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    if ((*visible)[i] == 0) continue;
    const Eigen::Vector3d in_camera = camera.ToCamera(points.col(i));
    const Eigen::Vector3d pixel = camera.K * in_camera;
    const double x = std::round(pixel.x() / pixel.z()), y = std::round(pixel.y() / pixel.z());
    const bool inside =
        in_camera.z() > 0.0 && x >= 0.0 && y >= 0.0 && x < camera.width && y < camera.height;
    if (!inside || foreground.at<unsigned char>(static_cast<int>(y), static_cast<int>(x)) == 0) {
      (*visible)[i] = 0;
    }
  }
}

std::vector<cv::Mat> ForegroundImages(const FrameInput& input) {
  if (input.masks.empty()) return input.images;
  std::vector<cv::Mat> images(input.images.size());
  for (size_t c = 0; c < images.size(); ++c) {
    images[c] = cv::Mat::zeros(input.images[c].size(), input.images[c].type());
    input.images[c].copyTo(images[c], input.masks[c]);
  }
  return images;
}

}  // namespace finecap
