// Which surface points fall on a camera's foreground: how a mask (FrameInput::masks) takes
// background pixels out of the energy's visibility.
#ifndef FINECAP_SRC_REFINE_FOREGROUND_H_
#define FINECAP_SRC_REFINE_FOREGROUND_H_

#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "finecap/geometry/camera.h"
#include "finecap/refine/refine.h"

namespace finecap {

// Clears visible[i] for each point i (a column of `points`, world coordinates) whose nearest
// pixel in `camera` (pinhole, undistorted) is outside the image or on the background of `mask`
// (CV_8UC1 of the camera's size, zero on the background) after the foreground is shrunk by
// `margin` pixels: a read that reaches `margin` pixels about the point then sees no background.
// Points already unseen are left alone.
void KeepForeground(const Camera& camera, const cv::Mat& mask, const Eigen::Matrix3Xd& points,
                    int margin, std::vector<unsigned char>* visible);

// The images of `input` with their background (FrameInput::masks) painted black, so that what
// reads pixels near a silhouette (a blur, a bilinear read, a weighted mean) takes nothing from
// the background whatever it holds; the images themselves (shared, not copied) without masks.
std::vector<cv::Mat> ForegroundImages(const FrameInput& input);

}  // namespace finecap

#endif  // FINECAP_SRC_REFINE_FOREGROUND_H_
