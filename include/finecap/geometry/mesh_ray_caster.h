// Where a line meets a triangle mesh: a bounding-volume hierarchy over the triangles answers
// "how far along this line is the surface" in logarithmic time. Used to measure the true
// displacement of a coarse vertex along its normal to the true surface.
#ifndef FINECAP_GEOMETRY_MESH_RAY_CASTER_H_
#define FINECAP_GEOMETRY_MESH_RAY_CASTER_H_

#include <optional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "finecap/geometry/mesh.h"

namespace finecap {

class MeshRayCaster {
 public:
  // Builds the hierarchy over a copy of `mesh`'s triangles (the mesh may change afterwards).
  // Throws Error if the mesh is invalid (see Mesh::Validate).
  explicit MeshRayCaster(const Mesh& mesh);

  // Of the points origin + t * direction with |t| <= max_distance that lie on a triangle, the
  // one nearest the origin: returns its signed t (in units of |direction|; metres for a unit
  // direction), or nothing when the line segment misses the mesh. Triangle edges and corners
  // count as hits, so a line through a vertex is never lost between its triangles.
  std::optional<double> NearestHit(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                                   double max_distance) const;

 private:
  struct Node {
    Eigen::Vector3d lower;
    Eigen::Vector3d upper;
    int first = 0;  // Leaf: first index into triangles_; inner node: index of the left child.
    int count = 0;  // Leaf: number of triangles; 0 for an inner node (right child = first + 1).
  };

  // Fills node `node` with the triangles_[begin, end), splitting them recursively, and returns
  // the exact bounds of their vertices (the node's box is these plus a little slack). An inner
  // node's bounds are its children's together: the vertices are read once, in the leaves.
  Eigen::AlignedBox3d Build(int node, int begin, int end, const Eigen::Matrix3Xd& centroids);

  Eigen::Matrix3Xd vertices_;
  Eigen::Matrix3Xi faces_;
  std::vector<int> triangles_;  // Face indices, ordered so that each leaf owns a contiguous range.
  std::vector<Node> nodes_;
};

}  // namespace finecap

#endif  // FINECAP_GEOMETRY_MESH_RAY_CASTER_H_
