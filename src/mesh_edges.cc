#include "finecap/mesh_edges.h"

#include <algorithm>
#include <cstdint>
#include <utility>

namespace finecap {
namespace {

// Orders edges by (smaller id, larger id) in one 64-bit comparison.
uint64_t EdgeKey(int a, int b) {
  const auto low = static_cast<uint32_t>(std::min(a, b));
  const auto high = static_cast<uint32_t>(std::max(a, b));
  return (static_cast<uint64_t>(low) << 32) | high;
}

}  // namespace

MeshEdges BuildMeshEdges(const Eigen::Matrix3Xi& faces) {
  const int num_faces = static_cast<int>(faces.cols());
  std::vector<std::pair<uint64_t, int>> keyed_sides;
  keyed_sides.reserve(3 * static_cast<size_t>(num_faces));
  for (int f = 0; f < num_faces; ++f) {
    for (int corner = 0; corner < 3; ++corner) {
      const int a = faces(corner, f);
      const int b = faces((corner + 1) % 3, f);
      if (a != b) keyed_sides.emplace_back(EdgeKey(a, b), 3 * f + corner);
    }
  }
  // Sorting on (key, side) also leaves the sides of every edge in increasing order.
  std::sort(keyed_sides.begin(), keyed_sides.end());

  MeshEdges edges;
  edges.face_edges = Eigen::Matrix3Xi::Constant(3, num_faces, -1);
  edges.sides.reserve(keyed_sides.size());
  std::vector<int> endpoints;
  for (size_t i = 0; i < keyed_sides.size(); ++i) {
    const uint64_t key = keyed_sides[i].first;
    if (i == 0 || key != keyed_sides[i - 1].first) {
      edges.side_offsets.push_back(static_cast<int>(i));
      endpoints.push_back(static_cast<int>(key >> 32));
      endpoints.push_back(static_cast<int>(key & 0xffffffffu));
    }
    const int side = keyed_sides[i].second;
    edges.sides.push_back(side);
    edges.face_edges(SideCorner(side), SideFace(side)) =
        static_cast<int>(edges.side_offsets.size()) - 1;
  }
  edges.side_offsets.push_back(static_cast<int>(keyed_sides.size()));
  edges.vertices = Eigen::Map<const Eigen::Matrix2Xi>(endpoints.data(), 2, endpoints.size() / 2);
  return edges;
}

}  // namespace finecap
