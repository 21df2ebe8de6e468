#include "finecap/geometry/bilinear.h"

#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

namespace finecap {
namespace {

// A 3-channel float image whose channels are smooth but not bilinear, so that the interpolant's
// derivative differs from place to place within a cell.
cv::Mat SmoothImage(int cols, int rows) {
  cv::Mat image(rows, cols, CV_32FC3);
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < cols; ++x) {
      image.at<cv::Vec3f>(y, x) =
          cv::Vec3f(std::sin(0.7 * x) + 0.1 * y * y, std::cos(0.4 * y) * x, 0.3 * x - 0.2 * y);
    }
  }
  return image;
}

// The interpolant passes through the pixels, whose centres are at integers.
TEST(BilinearTest, ReadsThePixelsAtTheirCentres) {
  const cv::Mat image = SmoothImage(9, 7);
  double color[3];
  ReadBilinear(image, 3.0, 2.0, 0.0, 0.0, color, nullptr);
  for (int channel = 0; channel < 3; ++channel) {
    EXPECT_NEAR(color[channel], image.at<cv::Vec3f>(2, 3)[channel], 1e-6);
  }
}

// A read's derivative along a direction is that of the interpolant itself (central differences
// within a cell), and the gradient read gives both axes' derivatives at once.
TEST(BilinearTest, DerivativesAreTheInterpolantsAndTheGradientReadsBothAxes) {
  const cv::Mat image = SmoothImage(9, 7);
  const double x = 4.3, y = 2.6, step = 1e-4;
  double along_x[3], along_y[3], gradient_x[3], gradient_y[3], ahead[3], behind[3], color[3];
  ReadBilinear(image, x, y, 1.0, 0.0, color, along_x);
  ReadBilinear(image, x, y, 0.0, 1.0, color, along_y);
  ReadCellGradient(CellAt(image, x, y, 1.0, 1.0), RowStep(image), gradient_x, gradient_y);
  ReadBilinear(image, x + step, y, 0.0, 0.0, ahead, nullptr);
  ReadBilinear(image, x - step, y, 0.0, 0.0, behind, nullptr);
  for (int channel = 0; channel < 3; ++channel) {
    EXPECT_NEAR(along_x[channel], (ahead[channel] - behind[channel]) / (2 * step), 1e-6);
    EXPECT_DOUBLE_EQ(gradient_x[channel], along_x[channel]);
    EXPECT_DOUBLE_EQ(gradient_y[channel], along_y[channel]);
  }
  ReadBilinear(image, x, y + step, 0.0, 0.0, ahead, nullptr);
  ReadBilinear(image, x, y - step, 0.0, 0.0, behind, nullptr);
  for (int channel = 0; channel < 3; ++channel) {
    EXPECT_NEAR(along_y[channel], (ahead[channel] - behind[channel]) / (2 * step), 1e-6);
  }
}

// Outside the image the read is clamped to its border, where the derivative across it is zero
// and the one along it stays.
TEST(BilinearTest, ClampsToTheBorderWithNoDerivativeAcrossIt) {
  const cv::Mat image = SmoothImage(9, 7);
  double gradient_x[3], gradient_y[3];
  ReadCellGradient(CellAt(image, -2.0, 3.5, 1.0, 1.0), RowStep(image), gradient_x, gradient_y);
  double inside_x[3], inside_y[3];
  ReadCellGradient(CellAt(image, 0.0, 3.5, 1.0, 1.0), RowStep(image), inside_x, inside_y);
  for (int channel = 0; channel < 3; ++channel) {
    EXPECT_EQ(gradient_x[channel], 0.0);
    EXPECT_DOUBLE_EQ(gradient_y[channel], inside_y[channel]);
  }
  EXPECT_NE(inside_y[0], 0.0);
}

}  // namespace
}  // namespace finecap
