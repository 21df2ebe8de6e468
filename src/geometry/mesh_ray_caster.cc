#include "finecap/geometry/mesh_ray_caster.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include <Eigen/Geometry>

namespace finecap {
namespace {

constexpr int kLeafSize = 4;

// The part [t_min, t_max] of the parameter range of the line that lies inside the box; empty
// when t_min > t_max.
void ClipToBox(const Eigen::Vector3d& lower, const Eigen::Vector3d& upper,
               const Eigen::Vector3d& origin, const Eigen::Vector3d& inverse_direction,
               double* t_min, double* t_max) {
  for (int axis = 0; axis < 3; ++axis) {
    double t0 = (lower(axis) - origin(axis)) * inverse_direction(axis);
    double t1 = (upper(axis) - origin(axis)) * inverse_direction(axis);
    if (std::isnan(t0) || std::isnan(t1)) {
      // The line runs parallel to this slab: inside it or not at all.
      if (origin(axis) < lower(axis) || origin(axis) > upper(axis)) *t_min = *t_max + 1.0;
      continue;
    }
    if (t0 > t1) std::swap(t0, t1);
    *t_min = std::max(*t_min, t0);
    *t_max = std::min(*t_max, t1);
  }
}

// Moeller-Trumbore; edges count as inside (with a relative tolerance) so that a line through a
// shared edge or vertex is not lost.
std::optional<double> IntersectTriangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                        const Eigen::Vector3d& c, const Eigen::Vector3d& origin,
                                        const Eigen::Vector3d& direction) {
  constexpr double kEdgeTolerance = 1e-9;
  const Eigen::Vector3d ab = b - a;
  const Eigen::Vector3d ac = c - a;
  const Eigen::Vector3d p = direction.cross(ac);
  const double determinant = ab.dot(p);
  if (std::abs(determinant) < 1e-300) return std::nullopt;
  const double inverse = 1.0 / determinant;
  const Eigen::Vector3d to_origin = origin - a;
  const double u = to_origin.dot(p) * inverse;
  if (u < -kEdgeTolerance || u > 1.0 + kEdgeTolerance) return std::nullopt;
  const Eigen::Vector3d q = to_origin.cross(ab);
  const double v = direction.dot(q) * inverse;
  if (v < -kEdgeTolerance || u + v > 1.0 + kEdgeTolerance) return std::nullopt;
  return ac.dot(q) * inverse;
}

}  // namespace

MeshRayCaster::MeshRayCaster(const Mesh& mesh) : vertices_(mesh.vertices), faces_(mesh.faces) {
  mesh.Validate("ray caster mesh");
  Eigen::Matrix3Xd centroids(3, mesh.num_faces());
  for (int f = 0; f < mesh.num_faces(); ++f) {
    centroids.col(f) =
        (vertices_.col(faces_(0, f)) + vertices_.col(faces_(1, f)) + vertices_.col(faces_(2, f))) /
        3.0;
  }
  triangles_.resize(mesh.num_faces());
  std::iota(triangles_.begin(), triangles_.end(), 0);
  nodes_.reserve(2 * mesh.num_faces() / kLeafSize + 2);
  nodes_.emplace_back();
  Build(0, 0, mesh.num_faces(), centroids);
}

Eigen::AlignedBox3d MeshRayCaster::Build(int node, int begin, int end,
                                         const Eigen::Matrix3Xd& centroids) {
  Eigen::AlignedBox3d bounds;
  if (end - begin <= kLeafSize) {
    for (int i = begin; i < end; ++i) {
      for (int corner = 0; corner < 3; ++corner) {
        bounds.extend(vertices_.col(faces_(corner, triangles_[i])));
      }
    }
    nodes_[node].first = begin;
    nodes_[node].count = end - begin;
  } else {
    Eigen::AlignedBox3d centroid_bounds;
    for (int i = begin; i < end; ++i) centroid_bounds.extend(centroids.col(triangles_[i]));
    int axis = 0;
    centroid_bounds.sizes().maxCoeff(&axis);
    const int middle = (begin + end) / 2;
    std::nth_element(triangles_.begin() + begin, triangles_.begin() + middle,
                     triangles_.begin() + end,
                     [&](int a, int b) { return centroids(axis, a) < centroids(axis, b); });
    const int children = static_cast<int>(nodes_.size());
    nodes_.emplace_back();
    nodes_.emplace_back();
    nodes_[node].first = children;
    nodes_[node].count = 0;
    bounds = Build(children, begin, middle, centroids);
    bounds.extend(Build(children + 1, middle, end, centroids));
  }
  // A little slack: a line through a vertex on the box's face must not be rounded out of it.
  const double slack = 1e-9 * bounds.sizes().maxCoeff() + 1e-12;
  nodes_[node].lower = bounds.min().array() - slack;
  nodes_[node].upper = bounds.max().array() + slack;
  return bounds;
}

std::optional<double> MeshRayCaster::NearestHit(const Eigen::Vector3d& origin,
                                                const Eigen::Vector3d& direction,
                                                double max_distance) const {
  const Eigen::Vector3d inverse_direction = direction.cwiseInverse();
  std::optional<double> best;
  double best_distance = max_distance;
  std::vector<int> stack = {0};
  while (!stack.empty()) {
    const Node& node = nodes_[stack.back()];
    stack.pop_back();
    double t_min = -best_distance;
    double t_max = best_distance;
    ClipToBox(node.lower, node.upper, origin, inverse_direction, &t_min, &t_max);
    if (t_min > t_max) continue;
    // Nearest |t| the box can still offer.
    const double closest =
        (t_min <= 0.0 && t_max >= 0.0) ? 0.0 : std::min(std::abs(t_min), std::abs(t_max));
    if (closest > best_distance) continue;
    if (node.count == 0) {
      stack.push_back(node.first);
      stack.push_back(node.first + 1);
      continue;
    }
    for (int i = node.first; i < node.first + node.count; ++i) {
      const int face = triangles_[i];
      const std::optional<double> t =
          IntersectTriangle(vertices_.col(faces_(0, face)), vertices_.col(faces_(1, face)),
                            vertices_.col(faces_(2, face)), origin, direction);
      if (t && std::abs(*t) <= best_distance && (!best || std::abs(*t) < std::abs(*best))) {
        best = t;
        best_distance = std::abs(*t);
      }
    }
  }
  return best;
}

}  // namespace finecap
