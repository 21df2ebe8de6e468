// A small scene for energy tests, made in code: a grid of surface Gaussians on a gently curved
// sheet in front of a few cameras, with image Gaussians scattered over the sheet's projection.
#ifndef FINECAP_TESTS_ENERGY_FIXTURE_H_
#define FINECAP_TESTS_ENERGY_FIXTURE_H_

#include <memory>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "finecap/energy/frame_energy.h"
#include "finecap/geometry/mesh.h"

namespace finecap {

// A rows x cols grid mesh around the origin (spacing in metres), z = curvature/2 (x^2 + y^2).
inline Mesh GridMesh(int rows, int cols, double spacing, double curvature = 1.0) {
  Mesh mesh;
  mesh.vertices.resize(3, rows * cols);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const double x = (c - 0.5 * (cols - 1)) * spacing, y = (r - 0.5 * (rows - 1)) * spacing;
      mesh.vertices.col(r * cols + c) = Eigen::Vector3d(x, y, 0.5 * curvature * (x * x + y * y));
    }
  }
  mesh.faces.resize(3, 2 * (rows - 1) * (cols - 1));
  int f = 0;
  for (int r = 0; r + 1 < rows; ++r) {
    for (int c = 0; c + 1 < cols; ++c) {
      const int v = r * cols + c;
      // Counter-clockwise seen from -z, where the cameras are: normals point at them.
      mesh.faces.col(f++) = Eigen::Vector3i(v, v + cols, v + 1);
      mesh.faces.col(f++) = Eigen::Vector3i(v + 1, v + cols, v + cols + 1);
    }
  }
  return mesh;
}

// A camera `distance` metres from the origin on the -z side, tilted by `tilt` radians about y,
// looking at the origin.
inline Camera LookAtOrigin(double distance, double tilt, double focal, int size) {
  Camera camera;
  camera.name = "cam";
  camera.width = camera.height = size;
  camera.K << focal, 0.0, 0.5 * (size - 1), 0.0, focal, 0.5 * (size - 1), 0.0, 0.0, 1.0;
  const Eigen::Vector3d center = distance * Eigen::Vector3d(std::sin(tilt), 0.0, -std::cos(tilt));
  const Eigen::Vector3d forward = -center.normalized();
  const Eigen::Vector3d right = Eigen::Vector3d::UnitY().cross(forward).normalized();
  const Eigen::Vector3d down = forward.cross(right);
  camera.R.row(0) = right.transpose();
  camera.R.row(1) = down.transpose();
  camera.R.row(2) = forward.transpose();
  camera.t = -camera.R * center;
  return camera;
}

struct EnergyScene {
  Mesh mesh;
  SurfaceGaussians surface;
  std::vector<std::unique_ptr<ImageGaussians>> images;
  std::vector<CameraInput> cameras;
  VertexNeighbourhoods neighbourhoods;
};

// `tilts` give one camera each. Image Gaussians: `per_surface` random ones around each surface
// Gaussian's projection, with colours near its colour (so that colour weights are not all zero).
inline EnergyScene MakeEnergyScene(const std::vector<double>& tilts, int per_surface,
                                   unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  EnergyScene scene;
  scene.mesh = GridMesh(6, 6, 0.01);
  const Eigen::Matrix3Xd normals = ComputeVertexNormals(scene.mesh);
  ReferenceColors colors;
  colors.color_space = ColorSpace::kNormalizedRgb;
  colors.sigma_hat = 0.007;
  for (int v = 0; v < scene.mesh.num_vertices(); ++v) {
    colors.colors.push_back(
        Eigen::Vector3f(0.5 + 0.3 * unit(rng), 0.5 + 0.3 * unit(rng), 0.5 + 0.3 * unit(rng)));
    colors.valid.push_back(1);
  }
  std::vector<int> ids(scene.mesh.num_vertices());
  for (int v = 0; v < scene.mesh.num_vertices(); ++v) ids[v] = v;
  scene.surface = MakeSurfaceGaussians(scene.mesh.vertices, normals, ids, colors);
  scene.neighbourhoods = BuildVertexNeighbourhoods(scene.mesh, 2);
  for (double tilt : tilts) {
    CameraInput input;
    input.camera = LookAtOrigin(1.0, tilt, 400.0, 200);
    std::vector<ImageGaussian> gaussians;
    for (int s = 0; s < scene.surface.size(); ++s) {
      const Eigen::Vector2d center = input.camera.Project(scene.surface.base.col(s));
      for (int n = 0; n < per_surface; ++n) {
        ImageGaussian g;
        g.x = static_cast<float>(center.x() + 4.0 * unit(rng));
        g.y = static_cast<float>(center.y() + 4.0 * unit(rng));
        g.sigma = static_cast<float>(1.0 + 1.5 * std::abs(unit(rng)));
        for (int ch = 0; ch < 3; ++ch) {
          g.color[ch] = scene.surface.colors[s][ch] + static_cast<float>(0.03 * unit(rng));
        }
        gaussians.push_back(g);
      }
    }
    scene.images.push_back(std::make_unique<ImageGaussians>(
        input.camera.width, input.camera.height, ColorSpace::kNormalizedRgb, gaussians, "test"));
    input.image = scene.images.back().get();
    input.visible.assign(scene.surface.size(), 1);
    scene.cameras.push_back(std::move(input));
  }
  return scene;
}

// A form of the energy for parameterised tests: (similarity, overlap).
using EnergyForm = std::tuple<std::string, std::string>;

// Each similarity with the printed and the exact overlap.
inline auto AllEnergyForms() {
  return ::testing::Combine(::testing::Values("paper", "surface_color", "consensus"),
                            ::testing::Values("printed", "exact"));
}

// "paper_exact" and so on: the test names of AllEnergyForms().
inline std::string EnergyFormName(const ::testing::TestParamInfo<EnergyForm>& info) {
  return std::get<0>(info.param) + "_" + std::get<1>(info.param);
}

// Displacements uniform in [-amplitude, amplitude], metres.
inline Eigen::VectorXd RandomK(int n, double amplitude, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  Eigen::VectorXd k(n);
  for (int s = 0; s < n; ++s) k[s] = amplitude * unit(rng);
  return k;
}

// Central differences of a scalar function of k, one coordinate at a time.
template <typename Function>
inline Eigen::VectorXd NumericGradient(const Function& f, const Eigen::VectorXd& k, double h) {
  Eigen::VectorXd gradient(k.size());
  for (int s = 0; s < k.size(); ++s) {
    Eigen::VectorXd plus = k, minus = k;
    plus[s] += h;
    minus[s] -= h;
    gradient[s] = (f(plus) - f(minus)) / (2.0 * h);
  }
  return gradient;
}

}  // namespace finecap

#endif  // FINECAP_TESTS_ENERGY_FIXTURE_H_
