#include "finecap/geometry/camera.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <Eigen/Geometry>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include "finecap/util/error.h"
#include "test_util.h"

namespace finecap {
namespace {

Camera MakeDistortedCamera() {
  Camera camera;
  camera.name = "cam0";
  camera.width = 1004;
  camera.height = 1004;
  camera.K << 1200.0, 0.0, 501.5, 0.0, 1180.0, 498.0, 0.0, 0.0, 1.0;
  camera.R =
      Eigen::AngleAxisd(0.3, Eigen::Vector3d(0.2, 1.0, -0.1).normalized()).toRotationMatrix();
  camera.t = Eigen::Vector3d(0.1, -0.2, 3.0);
  camera.distortion = {-0.21, 0.08, 0.001, -0.002, 0.01};
  return camera;
}

// The same camera with OpenCV's rational (k4, k5, k6) and thin prism (s1..s4) terms as well.
Camera MakeRationalCamera() {
  Camera camera = MakeDistortedCamera();
  camera.distortion = {-0.21,  0.08,  0.001, -0.002,  0.01,   0.04,
                       -0.015, 0.006, 0.002, -0.0007, 0.0015, 0.0004};
  return camera;
}

class CameraModelTest : public ::testing::TestWithParam<bool> {
 protected:
  Camera MakeCamera() const { return GetParam() ? MakeRationalCamera() : MakeDistortedCamera(); }
};

TEST_P(CameraModelTest, ProjectionMatchesOpenCv) {
  const Camera camera = MakeCamera();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> coordinate(-0.5, 0.5);
  std::vector<cv::Point3d> points;
  for (int i = 0; i < 50; ++i)
    points.emplace_back(coordinate(rng), coordinate(rng), coordinate(rng));

  cv::Mat rvec, K, R;
  cv::eigen2cv(camera.R, R);
  cv::Rodrigues(R, rvec);
  cv::eigen2cv(camera.K, K);
  const cv::Mat tvec = (cv::Mat_<double>(3, 1) << camera.t.x(), camera.t.y(), camera.t.z());
  const std::vector<double> dist(camera.distortion.begin(), camera.distortion.end());
  std::vector<cv::Point2d> expected;
  cv::projectPoints(points, rvec, tvec, K, dist, expected);

  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector2d pixel =
        camera.Project(Eigen::Vector3d(points[i].x, points[i].y, points[i].z));
    EXPECT_NEAR(pixel.x(), expected[i].x, 1e-8);
    EXPECT_NEAR(pixel.y(), expected[i].y, 1e-8);
  }
}

TEST_P(CameraModelTest, ProjectionJacobianMatchesCentralDifferences) {
  const Camera camera = MakeCamera();
  const Eigen::Vector3d point(0.13, -0.27, 0.31);
  Eigen::Matrix<double, 2, 3> analytic;
  camera.Project(point, &analytic);
  const double h = 1e-6;
  for (int axis = 0; axis < 3; ++axis) {
    Eigen::Vector3d step = Eigen::Vector3d::Zero();
    step(axis) = h;
    const Eigen::Vector2d numeric =
        (camera.Project(point + step) - camera.Project(point - step)) / (2.0 * h);
    EXPECT_LT((analytic.col(axis) - numeric).norm(), 1e-6 * numeric.norm() + 1e-6) << axis;
  }
}

INSTANTIATE_TEST_SUITE_P(FiveAndTwelveCoefficients, CameraModelTest, ::testing::Bool());

TEST(CameraTest, NearestRotationRepairsRoundedRotationsAndRefusesTheRest) {
  const Eigen::Matrix3d exact =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.3, -1.0, 0.4).normalized()).toRotationMatrix();
  // Rounded to 6 significant digits (a published calibration's 1.4e-6 is of this kind), to
  // single precision and to 4 decimals: each is accepted and comes back as the nearest rotation.
  for (const double step : {1e-6, 6e-8, 1e-4}) {
    Eigen::Matrix3d rounded = exact;
    for (int i = 0; i < 9; ++i) rounded(i) = std::round(exact(i) / step) * step;
    double deviation = 0.0;
    const Eigen::Matrix3d nearest = NearestRotation(rounded, "cameras.yaml", &deviation);
    EXPECT_GT(deviation, 0.0) << step;
    EXPECT_LT((nearest.transpose() * nearest - Eigen::Matrix3d::Identity()).norm(), 1e-14);
    EXPECT_NEAR(nearest.determinant(), 1.0, 1e-14);
    EXPECT_LT((nearest - exact).norm(), 10.0 * step) << step;
    Camera camera = MakeDistortedCamera();
    camera.R = nearest;
    EXPECT_NO_THROW(camera.Validate("cameras.yaml"));
  }
  const Eigen::Matrix3d scaled = 1.001 * exact;
  Eigen::Matrix3d sheared = exact;
  sheared(0, 1) += 0.01;
  const Eigen::Matrix3d reflected = -exact;
  for (const Eigen::Matrix3d& wrong :
       {scaled, sheared, reflected, Eigen::Matrix3d::Zero().eval()}) {
    testing_util::ExpectErrorMentions([&] { NearestRotation(wrong, "cameras.yaml (camera 'c')"); },
                                      {"cameras.yaml (camera 'c')", "not a rotation"});
  }
}

TEST(CameraTest, ValidateRejectsNonRotation) {
  Camera camera = MakeDistortedCamera();
  EXPECT_NO_THROW(camera.Validate("cameras.yaml"));
  camera.R(0, 0) *= 2.0;
  EXPECT_THROW(camera.Validate("cameras.yaml"), Error);
  camera.R = Eigen::Matrix3d::Zero();
  EXPECT_THROW(camera.Validate("cameras.yaml"), Error);
  camera.R = -Eigen::Matrix3d::Identity();  // A reflection: determinant -1.
  EXPECT_THROW(camera.Validate("cameras.yaml"), Error);
}

}  // namespace
}  // namespace finecap
