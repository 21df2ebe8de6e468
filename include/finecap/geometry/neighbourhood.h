// Vertex neighbourhoods on a mesh's edge graph, for the regulariser
//
//   E_reg = sum_s sum_{j in Psi(s)} T(delta_sj) * (k_s - k_j)^2,
//
// where Psi(s) holds the vertices at most Delta edges away from s (the paper uses Delta = 2) and
// delta_sj is the edge distance: the number of edges on a shortest path from s to j. Neighbourhoods
// depend on the connectivity only, so one structure serves every frame of a sequence.
#ifndef FINECAP_GEOMETRY_NEIGHBOURHOOD_H_
#define FINECAP_GEOMETRY_NEIGHBOURHOOD_H_

#include <string>
#include <vector>

#include "finecap/geometry/mesh.h"

namespace finecap {

// Psi(s) for every vertex s, stored flat (compressed rows): the neighbours of s are
// neighbours[offsets[s] .. offsets[s + 1]), sorted by vertex id, never containing s itself, and
// edge_distances[k] is the edge distance from s to neighbours[k], in 1 .. max_edge_distance.
// The relation is symmetric: j is in Psi(s) exactly when s is in Psi(j), at the same distance, so
// the double sum in E_reg visits every pair twice.
//
//   for (int k = n.offsets[s]; k < n.offsets[s + 1]; ++k) use(n.neighbours[k],
//   n.edge_distances[k]);
struct VertexNeighbourhoods {
  int max_edge_distance = 0;    // Delta, in edges.
  std::vector<int> offsets;     // num_vertices + 1 entries, offsets[0] = 0.
  std::vector<int> neighbours;  // Vertex ids.
  std::vector<int> edge_distances;

  int num_vertices() const { return offsets.empty() ? 0 : static_cast<int>(offsets.size()) - 1; }
  int num_neighbours(int s) const { return offsets[s + 1] - offsets[s]; }
  // Total number of (s, j) entries, i.e. twice the number of unordered pairs.
  int num_entries() const { return static_cast<int>(neighbours.size()); }
};

// Which shortest paths count when the neighbourhoods are restricted to a vertex subset.
enum class MaskedPaths {
  // Paths run through subset vertices only: the edge graph is cut to the subset first, so two
  // subset vertices joined only around an excluded region are farther apart (or not neighbours).
  kInsideMask,
  // Paths may run through any vertex; only the endpoints must be in the subset.
  kThroughAnyVertex,
};

// The one-ring adjacency: Psi(s) with Delta = 1, all distances 1. Isolated vertices get no
// neighbours. Throws Error(where, ...) when the mesh fails Mesh::Validate.
VertexNeighbourhoods BuildVertexAdjacency(const Mesh& mesh, const std::string& where = "mesh");

// Psi(s) for every vertex, by a breadth-first search of depth `max_edge_distance` from each vertex
// over the edge graph: O(V * |Psi|). Throws Error(where, ...) when the mesh fails Mesh::Validate
// or max_edge_distance < 1.
VertexNeighbourhoods BuildVertexNeighbourhoods(const Mesh& mesh, int max_edge_distance,
                                               const std::string& where = "mesh");

// Psi(s) restricted to the vertices s with vertex_mask[s] true (one entry per mesh vertex): only
// those vertices have neighbours and only they appear as neighbours; `paths` says which shortest
// paths count. Vertices outside the mask keep an empty list, so ids still index the structure.
// Throws Error(where, ...) also when the mask's size differs from the vertex count.
VertexNeighbourhoods BuildVertexNeighbourhoods(const Mesh& mesh, int max_edge_distance,
                                               const std::vector<bool>& vertex_mask,
                                               MaskedPaths paths = MaskedPaths::kInsideMask,
                                               const std::string& where = "mesh");

}  // namespace finecap

#endif  // FINECAP_GEOMETRY_NEIGHBOURHOOD_H_
