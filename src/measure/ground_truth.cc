#include "measure/ground_truth.h"

#include <cmath>
#include <vector>

#include "finecap/geometry/mesh_ray_caster.h"

namespace finecap {

Eigen::VectorXd TrueDisplacementAlongNormals(const Eigen::Matrix3Xd& vertices,
                                             const Eigen::Matrix3Xd& normals, const Mesh& truth,
                                             double max_distance) {
  const MeshRayCaster caster(truth);
  const int n = static_cast<int>(vertices.cols());
  Eigen::VectorXd displacement(n);
#pragma omp parallel for schedule(dynamic, 256)
  for (int v = 0; v < n; ++v) {
    const auto hit = caster.NearestHit(vertices.col(v), normals.col(v), max_distance);
    displacement[v] = hit ? *hit : std::nan("");
  }
  return displacement;
}

}  // namespace finecap
