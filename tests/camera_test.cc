#include "finecap/camera.h"

#include <random>

#include <gtest/gtest.h>
#include <Eigen/Geometry>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include "finecap/error.h"

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

TEST(CameraTest, ProjectionMatchesOpenCv) {
  const Camera camera = MakeDistortedCamera();
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

TEST(CameraTest, ProjectionJacobianMatchesCentralDifferences) {
  const Camera camera = MakeDistortedCamera();
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
