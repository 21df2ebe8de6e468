#include "finecap/geometry/neighbourhood.h"

#include <algorithm>
#include <utility>

#include "finecap/geometry/mesh_edges.h"
#include "finecap/util/error.h"

namespace finecap {
namespace {

// The one ring of every vertex from the sorted edge list. Because edges come sorted by
// (smaller, larger), each vertex first receives its smaller neighbours in increasing order and
// then its larger ones in increasing order: every list ends up sorted without a sort.
VertexNeighbourhoods OneRingFromEdges(int num_vertices, const MeshEdges& edges) {
  VertexNeighbourhoods ring;
  ring.max_edge_distance = 1;
  ring.offsets.assign(num_vertices + 1, 0);
  for (int e = 0; e < edges.num_edges(); ++e) {
    ++ring.offsets[edges.vertices(0, e) + 1];
    ++ring.offsets[edges.vertices(1, e) + 1];
  }
  for (int v = 0; v < num_vertices; ++v) ring.offsets[v + 1] += ring.offsets[v];
  ring.neighbours.resize(ring.offsets.back());
  std::vector<int> next(ring.offsets.begin(), ring.offsets.end() - 1);
  for (int e = 0; e < edges.num_edges(); ++e) {
    const int a = edges.vertices(0, e);
    const int b = edges.vertices(1, e);
    ring.neighbours[next[a]++] = b;
    ring.neighbours[next[b]++] = a;
  }
  ring.edge_distances.assign(ring.neighbours.size(), 1);
  return ring;
}

VertexNeighbourhoods ValidatedOneRing(const Mesh& mesh, const std::string& where) {
  mesh.Validate(where);
  return OneRingFromEdges(mesh.num_vertices(), BuildMeshEdges(mesh.faces));
}

// Breadth-first search of depth `max_edge_distance` from every included vertex. `visited_from[v]`
// holds the last source that reached v, so the marks never need clearing between sources.
VertexNeighbourhoods SearchRings(const VertexNeighbourhoods& ring, int max_edge_distance,
                                 const std::vector<bool>& included,
                                 const std::vector<bool>& traversable) {
  const int num_vertices = ring.num_vertices();
  VertexNeighbourhoods result;
  result.max_edge_distance = max_edge_distance;
  result.offsets.reserve(num_vertices + 1);
  result.offsets.push_back(0);
  std::vector<int> visited_from(num_vertices, -1);
  std::vector<int> frontier, next_frontier;
  std::vector<std::pair<int, int>> found;  // (neighbour, distance)
  for (int s = 0; s < num_vertices; ++s) {
    found.clear();
    if (included[s]) {
      visited_from[s] = s;
      frontier.assign(1, s);
      for (int distance = 1; distance <= max_edge_distance && !frontier.empty(); ++distance) {
        next_frontier.clear();
        for (const int u : frontier) {
          for (int k = ring.offsets[u]; k < ring.offsets[u + 1]; ++k) {
            const int w = ring.neighbours[k];
            if (visited_from[w] == s || !traversable[w]) continue;
            visited_from[w] = s;
            next_frontier.push_back(w);
            if (included[w]) found.emplace_back(w, distance);
          }
        }
        frontier.swap(next_frontier);
      }
      std::sort(found.begin(), found.end());
    }
    for (const auto& [neighbour, distance] : found) {
      result.neighbours.push_back(neighbour);
      result.edge_distances.push_back(distance);
    }
    result.offsets.push_back(static_cast<int>(result.neighbours.size()));
  }
  return result;
}

void RequirePositiveDistance(int max_edge_distance, const std::string& where) {
  Require(max_edge_distance >= 1, where,
          "the neighbourhood's largest edge distance must be at least 1, got " +
              std::to_string(max_edge_distance));
}

}  // namespace

VertexNeighbourhoods BuildVertexAdjacency(const Mesh& mesh, const std::string& where) {
  return ValidatedOneRing(mesh, where);
}

VertexNeighbourhoods BuildVertexNeighbourhoods(const Mesh& mesh, int max_edge_distance,
                                               const std::string& where) {
  RequirePositiveDistance(max_edge_distance, where);
  const VertexNeighbourhoods ring = ValidatedOneRing(mesh, where);
  if (max_edge_distance == 1) return ring;
  const std::vector<bool> everyone(mesh.num_vertices(), true);
  return SearchRings(ring, max_edge_distance, everyone, everyone);
}

VertexNeighbourhoods BuildVertexNeighbourhoods(const Mesh& mesh, int max_edge_distance,
                                               const std::vector<bool>& vertex_mask,
                                               MaskedPaths paths, const std::string& where) {
  RequirePositiveDistance(max_edge_distance, where);
  Require(static_cast<int>(vertex_mask.size()) == mesh.num_vertices(), where,
          "the vertex mask has " + std::to_string(vertex_mask.size()) +
              " entries but the mesh has " + std::to_string(mesh.num_vertices()) + " vertices");
  const VertexNeighbourhoods ring = ValidatedOneRing(mesh, where);
  const std::vector<bool> everyone(mesh.num_vertices(), true);
  return SearchRings(ring, max_edge_distance, vertex_mask,
                     paths == MaskedPaths::kInsideMask ? vertex_mask : everyone);
}

}  // namespace finecap
