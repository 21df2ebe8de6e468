#include "finecap/geometry/neighbourhood.h"

#include <algorithm>
#include <cstdlib>

#include <gtest/gtest.h>

#include "finecap/util/error.h"
#include "test_meshes.h"

namespace finecap {
namespace {

using testing_meshes::GridId;
using testing_meshes::GridMesh;
using testing_meshes::TubeMesh;

// Edge distance on the infinite grid of GridMesh: steps along x, y and the (1, 1) diagonal, so
// offsets of equal sign cost max(|dx|, |dy|) and offsets of opposite sign cost |dx| + |dy|.
int GridDistance(int dx, int dy) {
  if ((dx >= 0) == (dy >= 0)) return std::max(std::abs(dx), std::abs(dy));
  return std::abs(dx) + std::abs(dy);
}

// Distance from s to j in `n`, or 0 when j is not in Psi(s).
int DistanceIn(const VertexNeighbourhoods& n, int s, int j) {
  for (int k = n.offsets[s]; k < n.offsets[s + 1]; ++k) {
    if (n.neighbours[k] == j) return n.edge_distances[k];
  }
  return 0;
}

void ExpectSymmetricAndSorted(const VertexNeighbourhoods& n) {
  for (int s = 0; s < n.num_vertices(); ++s) {
    for (int k = n.offsets[s]; k < n.offsets[s + 1]; ++k) {
      const int j = n.neighbours[k];
      EXPECT_NE(j, s);
      if (k > n.offsets[s]) {
        EXPECT_LT(n.neighbours[k - 1], j) << "list of " << s << " unsorted";
      }
      EXPECT_EQ(DistanceIn(n, j, s), n.edge_distances[k]) << "pair " << s << ", " << j;
    }
  }
}

TEST(NeighbourhoodTest, GridCountsMatchHandDerivedValues) {
  const int columns = 7;
  const VertexNeighbourhoods n = BuildVertexNeighbourhoods(GridMesh(columns, 7), 2);
  ASSERT_EQ(n.num_vertices(), 49);
  EXPECT_EQ(n.max_edge_distance, 2);
  // Interior: 6 vertices at distance 1 and 12 at distance 2 (the hexagonal rings).
  const int centre = GridId(3, 3, columns);
  EXPECT_EQ(n.num_neighbours(centre), 18);
  EXPECT_EQ(std::count(n.edge_distances.begin() + n.offsets[centre],
                       n.edge_distances.begin() + n.offsets[centre + 1], 1),
            6);
  // Corner (0, 0): the 3 x 3 block minus itself. Corner (6, 0): (-1, 0), (-2, 0), (0, 1), (0, 2),
  // (-1, 1).
  EXPECT_EQ(n.num_neighbours(GridId(0, 0, columns)), 8);
  EXPECT_EQ(n.num_neighbours(GridId(6, 0, columns)), 5);
  EXPECT_EQ(DistanceIn(n, GridId(6, 0, columns), GridId(5, 1, columns)), 2);
  EXPECT_EQ(DistanceIn(n, GridId(0, 0, columns), GridId(1, 1, columns)), 1);
}

TEST(NeighbourhoodTest, GridDistancesMatchClosedForm) {
  const int columns = 6, rows = 5;
  const VertexNeighbourhoods n = BuildVertexNeighbourhoods(GridMesh(columns, rows), 3);
  // The grid is convex, so its shortest paths are those of the infinite grid.
  for (int sy = 0; sy < rows; ++sy) {
    for (int sx = 0; sx < columns; ++sx) {
      int expected_count = 0;
      for (int y = 0; y < rows; ++y) {
        for (int x = 0; x < columns; ++x) {
          const int distance = GridDistance(x - sx, y - sy);
          const bool expected = distance >= 1 && distance <= 3;
          expected_count += expected;
          EXPECT_EQ(DistanceIn(n, GridId(sx, sy, columns), GridId(x, y, columns)),
                    expected ? distance : 0);
        }
      }
      EXPECT_EQ(n.num_neighbours(GridId(sx, sy, columns)), expected_count);
    }
  }
}

TEST(NeighbourhoodTest, AdjacencyIsTheOneRing) {
  const Mesh tube = TubeMesh(8, 4);
  const VertexNeighbourhoods ring = BuildVertexAdjacency(tube);
  const VertexNeighbourhoods one_ring = BuildVertexNeighbourhoods(tube, 1);
  EXPECT_EQ(ring.offsets, one_ring.offsets);
  EXPECT_EQ(ring.neighbours, one_ring.neighbours);
  EXPECT_EQ(ring.edge_distances, one_ring.edge_distances);
  // Hem vertices have valence 4, the others 6; 2E entries with E = 8 * 3 * 3 + 8.
  EXPECT_EQ(ring.num_neighbours(0), 4);
  EXPECT_EQ(ring.num_neighbours(9), 6);
  EXPECT_EQ(ring.num_entries(), 2 * 80);
  ExpectSymmetricAndSorted(ring);
}

TEST(NeighbourhoodTest, TubeNeighbourhoodsAreSymmetric) {
  ExpectSymmetricAndSorted(BuildVertexNeighbourhoods(TubeMesh(10, 6), 3));
}

TEST(NeighbourhoodTest, MaskedPathsStayInsideTheMaskOrRunAnywhere) {
  const int columns = 5;
  const Mesh grid = GridMesh(columns, 5);
  // Everything but the middle column, except its top vertex: a wall with a gap at the top.
  std::vector<bool> mask(grid.num_vertices(), true);
  for (int y = 0; y < 4; ++y) mask[GridId(2, y, columns)] = false;
  const int left = GridId(1, 2, columns), right = GridId(3, 2, columns);

  const VertexNeighbourhoods inside = BuildVertexNeighbourhoods(grid, 2, mask);
  const VertexNeighbourhoods anywhere =
      BuildVertexNeighbourhoods(grid, 2, mask, MaskedPaths::kThroughAnyVertex);
  EXPECT_EQ(DistanceIn(inside, left, right), 0);
  EXPECT_EQ(DistanceIn(anywhere, left, right), 2);
  // Around the gap: (1, 3) -> (2, 4) -> (3, 4) is 2 edges inside the mask.
  EXPECT_EQ(DistanceIn(inside, GridId(1, 3, columns), GridId(3, 4, columns)), 2);
  for (const VertexNeighbourhoods* n : {&inside, &anywhere}) {
    ExpectSymmetricAndSorted(*n);
    for (int v = 0; v < grid.num_vertices(); ++v) {
      if (!mask[v]) {
        EXPECT_EQ(n->num_neighbours(v), 0);
      }
    }
    for (const int j : n->neighbours) EXPECT_TRUE(mask[j]);
  }
}

TEST(NeighbourhoodTest, RefusesBadInputWithAMessage) {
  const Mesh grid = GridMesh(3, 3);
  try {
    BuildVertexNeighbourhoods(grid, 2, std::vector<bool>(5, true), MaskedPaths::kInsideMask,
                              "mask.txt");
    FAIL() << "no error";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("mask.txt"), std::string::npos);
    EXPECT_NE(std::string(error.what()).find("5 entries but the mesh has 9"), std::string::npos);
  }
  EXPECT_THROW(BuildVertexNeighbourhoods(grid, 0), Error);
  Mesh broken = grid;
  broken.faces(1, 0) = 42;
  try {
    BuildVertexAdjacency(broken, "body.ply");
    FAIL() << "no error";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("body.ply"), std::string::npos);
    EXPECT_NE(std::string(error.what()).find("does not exist"), std::string::npos);
  }
}

}  // namespace
}  // namespace finecap
