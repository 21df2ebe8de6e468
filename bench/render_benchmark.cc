// Rendering cost of one capture frame: eight 1004 x 1004 cameras on a ring around a textured
// ~40k-triangle subject, the size of the synthetic skirt captures.
#include <cmath>
#include <vector>

#include <benchmark/benchmark.h>
#include <Eigen/Geometry>

#include "../tests/test_meshes.h"
#include "finecap/geometry/render.h"

namespace finecap {
namespace {

std::vector<Camera> MakeRing(int count) {
  std::vector<Camera> cameras;
  for (int c = 0; c < count; ++c) {
    const double angle = 2.0 * M_PI * c / count;
    const Eigen::Vector3d center(3.0 * std::cos(angle), 0.2, 3.0 * std::sin(angle));
    const Eigen::Vector3d z = (-center).normalized();
    const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitY()).normalized();
    Camera camera;
    camera.name = "cam" + std::to_string(c);
    camera.width = camera.height = 1004;
    camera.K << 1000.0, 0.0, 501.5, 0.0, 1000.0, 501.5, 0.0, 0.0, 1.0;
    camera.R.row(0) = x;
    camera.R.row(1) = z.cross(x);
    camera.R.row(2) = z;
    camera.t = -camera.R * center;
    cameras.push_back(camera);
  }
  return cameras;
}

SurfaceAppearance MakeTexturedAppearance(const Mesh& mesh) {
  SurfaceAppearance appearance;
  appearance.texture = cv::Mat(1024, 2048, CV_8UC3);
  cv::randu(appearance.texture, cv::Scalar::all(0), cv::Scalar::all(255));
  appearance.corner_uvs.resize(2, 3 * mesh.num_faces());
  for (int f = 0; f < mesh.num_faces(); ++f) {
    for (int c = 0; c < 3; ++c) {
      const Eigen::Vector3d p = mesh.vertices.col(mesh.faces(c, f));
      appearance.corner_uvs.col(3 * f + c) = Eigen::Vector2d(p.x() + 0.5, p.y() + 0.5);
    }
  }
  return appearance;
}

void BM_RenderColorEightCameras(benchmark::State& state) {
  const Mesh mesh = testing_meshes::SphereMesh(Eigen::Vector3d::Zero(), 0.4, 100, 200);
  const std::vector<Camera> cameras = MakeRing(8);
  const SurfaceAppearance appearance = MakeTexturedAppearance(mesh);
  RenderOptions options;
  options.supersampling = static_cast<int>(state.range(0));
  options.shade = true;
  for (auto _ : state) {
    for (const Camera& camera : cameras) {
      benchmark::DoNotOptimize(RenderColor(camera, mesh, appearance, options).data);
    }
  }
  state.counters["triangles"] = mesh.num_faces();
}
BENCHMARK(BM_RenderColorEightCameras)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_RenderDepthEightCameras(benchmark::State& state) {
  const Mesh mesh = testing_meshes::SphereMesh(Eigen::Vector3d::Zero(), 0.4, 100, 200);
  const std::vector<Camera> cameras = MakeRing(8);
  for (auto _ : state) {
    for (const Camera& camera : cameras) {
      benchmark::DoNotOptimize(RenderDepth(camera, mesh).depth.data);
    }
  }
}
BENCHMARK(BM_RenderDepthEightCameras)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace finecap

BENCHMARK_MAIN();
