// Taubin smoothing: bumps fade, the shape keeps its size, vertices stay where they were on the
// surface (little tangential drift), the topology is untouched, and bad strengths are refused.
#include "finecap/geometry/mesh_smoothing.h"

#include <cmath>

#include <gtest/gtest.h>

#include "finecap/util/error.h"
#include "test_meshes.h"
#include "test_util.h"

namespace finecap {
namespace {

using testing_util::ExpectErrorMentions;

constexpr int kAround = 48;
constexpr int kRows = 24;
constexpr double kRadius = 0.3;
constexpr double kHeight = 0.6;
constexpr double kBump = 0.004;

// A tube of radius kRadius around the z axis whose radius carries bumps of 4 edges' wavelength,
// 12 around and 6 along the axis.
Mesh BumpyTube() {
  Mesh mesh = testing_meshes::TubeMesh(kAround, kRows, kRadius, kHeight);
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    const double theta = std::atan2(mesh.vertices(1, v), mesh.vertices(0, v));
    const double z = mesh.vertices(2, v);
    const double bump = kBump * std::sin(12.0 * theta) * std::sin(2.0 * M_PI * 6.0 * z / kHeight);
    mesh.vertices.col(v).head<2>() *= (kRadius + bump) / kRadius;
  }
  return mesh;
}

Eigen::VectorXd Radii(const Eigen::Matrix3Xd& vertices) {
  return (vertices.row(0).array().square() + vertices.row(1).array().square()).sqrt();
}

// RMS of (radius - kRadius) over the rows away from the tube's open ends.
double RmsRadialDeviation(const Eigen::Matrix3Xd& vertices, double* mean_radius) {
  const Eigen::VectorXd radii = Radii(vertices);
  double sum = 0.0, squares = 0.0;
  int count = 0;
  for (int v = 2 * kAround; v < (kRows - 2) * kAround; ++v) {
    sum += radii(v);
    squares += (radii(v) - kRadius) * (radii(v) - kRadius);
    ++count;
  }
  *mean_radius = sum / count;
  return std::sqrt(squares / count);
}

TEST(MeshSmoothingTest, BumpsFadeWhileTheTubeKeepsItsSize) {
  const Mesh tube = BumpyTube();
  TaubinSmoothingOptions options;
  options.iterations = 20;
  Mesh smoothed = tube;
  smoothed.vertices = TaubinSmooth(tube, options);
  EXPECT_EQ(smoothed.vertices.cols(), tube.vertices.cols());

  double mean_before = 0.0, mean_after = 0.0;
  const double before = RmsRadialDeviation(tube.vertices, &mean_before);
  const double after = RmsRadialDeviation(smoothed.vertices, &mean_after);
  EXPECT_GT(before, 0.4 * kBump);
  EXPECT_LT(after, 0.2 * before) << "before " << before << " after " << after;

  // Plain Laplacian smoothing (mu = 0) with the same lambda shrinks the tube; Taubin's mu step
  // inflates it back.
  TaubinSmoothingOptions laplacian = options;
  laplacian.mu = 0.0;
  double mean_laplacian = 0.0;
  RmsRadialDeviation(TaubinSmooth(tube, laplacian), &mean_laplacian);
  const double shrink_taubin = std::abs(mean_after - mean_before);
  const double shrink_laplacian = std::abs(mean_laplacian - mean_before);
  EXPECT_GT(shrink_laplacian, 1e-4);
  EXPECT_LT(shrink_taubin, 0.2 * shrink_laplacian)
      << "Taubin " << shrink_taubin << " Laplacian " << shrink_laplacian;
}

// A sheet in the plane z = 0, its columns graded (spacing grows 4x from left to right, as a mesh
// that is finer in one place than another), with bumps in z.
Mesh GradedBumpySheet() {
  constexpr int kColumns = 32;
  Mesh sheet = testing_meshes::GridMesh(kColumns, 20);
  for (int v = 0; v < sheet.num_vertices(); ++v) {
    const double s = sheet.vertices(0, v) / (kColumns - 1);
    const double x = 0.5 * (s + 1.5 * s * s);  // Spacing from 0.5/31 to 2/31 of a metre.
    const double y = 0.03 * sheet.vertices(1, v);
    const double z = 0.003 * std::sin(2.0 * M_PI * y / 0.12) * std::cos(2.0 * M_PI * x / 0.2);
    sheet.vertices.col(v) << x, y, z;
  }
  return sheet;
}

TEST(MeshSmoothingTest, VerticesMoveAlongTheNormalNotOverTheSurface) {
  const Mesh sheet = GradedBumpySheet();
  TaubinSmoothingOptions options;
  options.iterations = 20;
  const Eigen::Matrix3Xd smoothed = TaubinSmooth(sheet, options);
  const Eigen::Matrix3Xd moved = smoothed - sheet.vertices;
  // The sheet's plane is the smooth surface: z is the normal part of the motion, (x, y) the
  // tangential drift.
  const double normal_rms = std::sqrt(moved.row(2).squaredNorm() / moved.cols());
  const double drift_rms = std::sqrt(moved.topRows(2).squaredNorm() / moved.cols());
  const double drift_max = moved.topRows(2).colwise().norm().maxCoeff();
  const double bumps_before = std::sqrt(sheet.vertices.row(2).squaredNorm() / moved.cols());
  const double bumps_after = std::sqrt(smoothed.row(2).squaredNorm() / moved.cols());
  EXPECT_LT(bumps_after, 0.5 * bumps_before) << bumps_before << " -> " << bumps_after;
  EXPECT_GT(normal_rms, 0.3 * bumps_before);
  // The closest columns are 16 mm apart: the drift is a small fraction of a millimetre, a few
  // per cent of the normal motion (only where the bumps tilt the normal).
  EXPECT_LT(drift_rms, 0.1 * normal_rms) << "drift " << drift_rms << " normal " << normal_rms;
  EXPECT_LT(drift_max, 5e-4) << drift_max;
}

TEST(MeshSmoothingTest, ALooseVertexStaysAndFacesAreKept) {
  Mesh tube = BumpyTube();
  tube.vertices.conservativeResize(3, tube.vertices.cols() + 1);
  tube.vertices.col(tube.vertices.cols() - 1) << 5.0, 6.0, 7.0;  // In no triangle.
  const Eigen::Matrix3Xd smoothed = TaubinSmooth(tube, TaubinSmoothingOptions());
  EXPECT_EQ(smoothed.col(smoothed.cols() - 1), Eigen::Vector3d(5.0, 6.0, 7.0));
  EXPECT_TRUE(smoothed.allFinite());
}

TEST(MeshSmoothingTest, StrengthsOutOfRangeAreRefusedNamingTheField) {
  TaubinSmoothingOptions options;
  EXPECT_NO_THROW(options.Check("synth.smoothing"));
  options.iterations = 0;
  ExpectErrorMentions([&] { options.Check("synth.smoothing"); },
                      {"synth.smoothing.iterations", "[1, 100000]"});
  options = TaubinSmoothingOptions();
  options.lambda = 0.0;
  ExpectErrorMentions([&] { options.Check("synth.smoothing"); }, {"synth.smoothing.lambda"});
  options = TaubinSmoothingOptions();
  options.mu = 0.3;
  ExpectErrorMentions([&] { options.Check("synth.smoothing"); }, {"synth.smoothing.mu"});
  options.mu = std::nan("");
  ExpectErrorMentions([&] { options.Check("synth.smoothing"); }, {"synth.smoothing.mu", "finite"});
  // Each in range, together unstable: (1 - 2 * 0.95)(1 + 2 * 1) = -2.7.
  options.lambda = 0.95;
  options.mu = -1.0;
  ExpectErrorMentions([&] { options.Check("synth.smoothing"); },
                      {"synth.smoothing.mu", "unstable"});
  // Taubin's own example values are accepted.
  options.lambda = 0.6307;
  options.mu = -0.6732;
  EXPECT_NO_THROW(options.Check("synth.smoothing"));
  const Mesh tube = BumpyTube();
  options.iterations = -3;
  EXPECT_THROW(TaubinSmooth(tube, options), Error);
}

}  // namespace
}  // namespace finecap
