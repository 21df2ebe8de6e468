// The undirected edges of a triangle mesh and the triangles on each of them: the connectivity that
// neighbourhoods, Loop subdivision and the mesh diagnostics are built from.
#ifndef FINECAP_GEOMETRY_MESH_EDGES_H_
#define FINECAP_GEOMETRY_MESH_EDGES_H_

#include <vector>

#include <Eigen/Core>

namespace finecap {

// A triangle side is encoded as 3 * face + corner: the side of triangle `face` running from its
// corner `corner` to its corner (corner + 1) % 3, so its direction follows the triangle's order.
inline int SideFace(int side) { return side / 3; }
inline int SideCorner(int side) { return side % 3; }

struct MeshEdges {
  // Endpoints of each edge, the smaller vertex id first. Edges are sorted by (first, second), so
  // an edge's id depends on the connectivity only, never on the order of the triangles.
  Eigen::Matrix2Xi vertices;
  // The triangle sides lying on edge e are sides[side_offsets[e] .. side_offsets[e + 1]), in
  // increasing order. One side: a boundary edge; two: an interior edge; three or more:
  // non-manifold.
  std::vector<int> side_offsets;
  std::vector<int> sides;
  // face_edges(corner, f) is the edge under triangle f's side starting at `corner`, or -1 when
  // that side's two corners are the same vertex (a collapsed triangle has no such edge).
  Eigen::Matrix3Xi face_edges;

  int num_edges() const { return static_cast<int>(vertices.cols()); }
  // Number of triangle sides on edge e, i.e. how many triangles contain it.
  int NumSides(int e) const { return side_offsets[e + 1] - side_offsets[e]; }
  bool IsBoundary(int e) const { return NumSides(e) == 1; }
};

// Collects the edges of `faces` by bucketing the 3 * num_faces sides on their smaller vertex, then
// sorting each bucket: O(F) for bounded valence. Vertex ids must be non-negative; the caller
// validates them against the vertex count.
MeshEdges BuildMeshEdges(const Eigen::Matrix3Xi& faces);

}  // namespace finecap

#endif  // FINECAP_GEOMETRY_MESH_EDGES_H_
