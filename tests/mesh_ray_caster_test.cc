#include "finecap/geometry/mesh_ray_caster.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "finecap/util/error.h"

namespace finecap {
namespace {

// The octahedron |x| + |y| + |z| = 1, subdivided nowhere: eight faces, exact planes.
Mesh MakeOctahedron() {
  Mesh mesh;
  mesh.vertices.resize(3, 6);
  mesh.vertices << 1, -1, 0, 0, 0, 0,  //
      0, 0, 1, -1, 0, 0,               //
      0, 0, 0, 0, 1, -1;
  mesh.faces.resize(3, 8);
  mesh.faces << 0, 2, 1, 3, 2, 1, 3, 0,  //
      2, 1, 3, 0, 0, 2, 1, 3,            //
      4, 4, 4, 4, 5, 5, 5, 5;
  return mesh;
}

TEST(MeshRayCasterTest, HitsTheOctahedronWhereTheL1SphereIs) {
  const MeshRayCaster caster(MakeOctahedron());
  std::mt19937 rng(5);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Vector3d direction =
        Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
    // From the centre the surface is 1 / |direction|_1 away, both ways.
    const std::optional<double> hit = caster.NearestHit(Eigen::Vector3d::Zero(), direction, 5.0);
    ASSERT_TRUE(hit.has_value());
    EXPECT_NEAR(std::abs(*hit), 1.0 / direction.lpNorm<1>(), 1e-12);
  }
}

TEST(MeshRayCasterTest, ReturnsTheSignedNearestHitWithinRange) {
  const MeshRayCaster caster(MakeOctahedron());
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX();
  // From (0.8, 0, 0): the face at x = 1 is 0.2 ahead, the one at x = -1 is 1.8 behind.
  EXPECT_NEAR(*caster.NearestHit(Eigen::Vector3d(0.8, 0, 0), x, 5.0), 0.2, 1e-12);
  EXPECT_NEAR(*caster.NearestHit(Eigen::Vector3d(0.8, 0, 0), -x, 5.0), -0.2, 1e-12);
  EXPECT_NEAR(*caster.NearestHit(Eigen::Vector3d(1.5, 0, 0), x, 5.0), -0.5, 1e-12);
  EXPECT_FALSE(caster.NearestHit(Eigen::Vector3d(1.5, 0, 0), x, 0.4).has_value());
  EXPECT_FALSE(caster.NearestHit(Eigen::Vector3d(0, 3, 0), x, 10.0).has_value());
}

TEST(MeshRayCasterTest, ManyTrianglesAgreeWithBruteForcePlane) {
  // A 60 x 60 grid on z = 0.1 x + 0.2 y: exercises the hierarchy's inner nodes.
  Mesh grid;
  const int n = 60;
  grid.vertices.resize(3, n * n);
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const double x = i / (n - 1.0);
      const double y = j / (n - 1.0);
      grid.vertices.col(j * n + i) = Eigen::Vector3d(x, y, 0.1 * x + 0.2 * y);
    }
  }
  grid.faces.resize(3, 2 * (n - 1) * (n - 1));
  int f = 0;
  for (int j = 0; j + 1 < n; ++j) {
    for (int i = 0; i + 1 < n; ++i) {
      const int a = j * n + i;
      grid.faces.col(f++) << a, a + 1, a + n + 1;
      grid.faces.col(f++) << a, a + n + 1, a + n;
    }
  }
  const MeshRayCaster caster(grid);
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> unit(0.05, 0.95);
  for (int trial = 0; trial < 300; ++trial) {
    const Eigen::Vector3d origin(unit(rng), unit(rng), 0.5);
    const Eigen::Vector3d direction = Eigen::Vector3d(0.1 * unit(rng), -0.1, -1.0).normalized();
    const Eigen::Vector3d n_plane(-0.1, -0.2, 1.0);
    const double expected = -n_plane.dot(origin) / n_plane.dot(direction);
    const std::optional<double> hit = caster.NearestHit(origin, direction, 2.0);
    ASSERT_TRUE(hit.has_value());
    EXPECT_NEAR(*hit, expected, 1e-12);
  }
}

TEST(MeshRayCasterTest, RefusesAnInvalidMesh) {
  Mesh mesh = MakeOctahedron();
  mesh.faces(0, 0) = 17;
  EXPECT_THROW(MeshRayCaster{mesh}, Error);
}

}  // namespace
}  // namespace finecap
