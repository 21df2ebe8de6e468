#include "finecap/geometry/subdivision.h"

#include <algorithm>
#include <random>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "finecap/geometry/mesh_edges.h"
#include "finecap/util/error.h"
#include "test_meshes.h"
#include "test_util.h"

namespace finecap {
namespace {

using testing_meshes::GridId;
using testing_meshes::GridMesh;
using testing_meshes::Icosahedron;
using testing_meshes::TubeMesh;
using testing_util::ExpectErrorMentions;

// Moves every vertex by a random offset, so that stencil weights show in the positions.
Mesh Jittered(Mesh mesh, double amount, unsigned seed = 3) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> offset(-amount, amount);
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    for (int axis = 0; axis < 3; ++axis) mesh.vertices(axis, v) += offset(rng);
  }
  return mesh;
}

// The fine id of the edge point between coarse vertices a and b after one level.
int EdgePoint(const SubdivisionStencil& stencil, int a, int b) {
  const Eigen::Matrix2Xi& edges = stencil.level_edges.at(0);
  for (int e = 0; e < edges.cols(); ++e) {
    if (edges(0, e) == std::min(a, b) && edges(1, e) == std::max(a, b)) {
      return stencil.num_coarse_vertices + e;
    }
  }
  ADD_FAILURE() << "no edge " << a << "-" << b;
  return 0;
}

// The unit cube, each face split along a diagonal into two outward triangles: corners of valence
// 3 to 6.
Mesh TriangulatedCube() {
  Mesh cube;
  cube.vertices.resize(3, 8);
  for (int v = 0; v < 8; ++v) {
    cube.vertices.col(v) << double(v & 1), double((v >> 1) & 1), double((v >> 2) & 1);
  }
  cube.vertices.array() -= 0.5;
  cube.faces.resize(3, 12);
  cube.faces << 0, 0, 4, 4, 0, 0, 2, 2, 0, 0, 1, 1,  //
      2, 3, 5, 7, 1, 5, 6, 7, 4, 6, 3, 7,            //
      3, 1, 7, 6, 5, 4, 7, 3, 6, 2, 7, 5;
  return cube;
}

// A fan of `valence` triangles around vertex 0 (at the origin, lifted by `lift`): the rim vertices
// 1 .. valence on a jittered circle, on the fan's boundary. Vertex 0 is interior, of that valence.
Mesh Fan(int valence, double lift = 0.3) {
  Mesh fan;
  fan.vertices.resize(3, valence + 1);
  fan.vertices.col(0) << 0.0, 0.0, lift;
  for (int i = 0; i < valence; ++i) {
    const double angle = 2.0 * M_PI * i / valence;
    fan.vertices.col(i + 1) << std::cos(angle), std::sin(angle), 0.0;
  }
  fan.faces.resize(3, valence);
  for (int i = 0; i < valence; ++i) fan.faces.col(i) << 0, i + 1, (i + 1) % valence + 1;
  return Jittered(fan, 0.1);
}

// Row `row` of S as (column, weight) pairs, sorted by column.
std::vector<std::pair<int, double>> Row(const SubdivisionStencil& stencil, int row) {
  const Eigen::SparseMatrix<double, Eigen::RowMajor> rows = stencil.matrix;
  std::vector<std::pair<int, double>> entries;
  for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(rows, row); it; ++it) {
    if (it.value() != 0.0) entries.emplace_back(static_cast<int>(it.col()), it.value());
  }
  return entries;
}

TEST(SubdivisionTest, VertexAndFaceCountsGrowByEdgesAndFour) {
  const Mesh ico = Icosahedron();
  EXPECT_EQ(BuildLoopSubdivision(ico, 0).num_fine_vertices(), 12);
  EXPECT_EQ(BuildLoopSubdivision(ico, 1).num_fine_vertices(), 12 + 30);
  const SubdivisionStencil two = BuildLoopSubdivision(ico, 2);
  EXPECT_EQ(two.num_fine_vertices(), 42 + 120);
  EXPECT_EQ(two.faces.cols(), 320);
  EXPECT_EQ(two.levels, 2);
  // The tube: V = 8 * 4, E = 80 (rings, verticals, diagonals).
  EXPECT_EQ(BuildLoopSubdivision(TubeMesh(8, 4), 1).num_fine_vertices(), 32 + 80);
}

TEST(SubdivisionTest, EveryRowSumsToOne) {
  for (const Mesh& mesh : {Icosahedron(), TubeMesh(7, 5), GridMesh(4, 3)}) {
    const SubdivisionStencil stencil = BuildLoopSubdivision(mesh, 2);
    const Eigen::VectorXd sums = stencil.matrix * Eigen::VectorXd::Ones(mesh.num_vertices());
    EXPECT_LT((sums.array() - 1.0).abs().maxCoeff(), 1e-12);
    EXPECT_GE(stencil.matrix.coeffs().minCoeff(), 0.0);
  }
}

TEST(SubdivisionTest, FirstFineVerticesAreTheCoarseOnesInOrder) {
  const Mesh tube = Jittered(TubeMesh(6, 3), 0.05);
  const SubdivisionStencil stencil = BuildLoopSubdivision(tube, 2);
  EXPECT_EQ(stencil.FineVertexOfCoarse(5), 5);
  EXPECT_THROW(stencil.FineVertexOfCoarse(18), Error);
  // The fine faces use coarse vertex v exactly where the coarse faces did, at the corners.
  const Mesh fine = ApplySubdivision(stencil, tube.vertices);
  for (int v = 0; v < tube.num_vertices(); ++v) {
    EXPECT_GT(stencil.matrix.coeff(v, v), 0.5);
    EXPECT_LT((fine.vertices.col(v) - tube.vertices.col(v)).norm(), 0.2);
  }
}

TEST(SubdivisionTest, RegularInteriorVertexAndEdgeFollowLoopsStencils) {
  const int columns = 5;
  const Mesh grid = Jittered(GridMesh(columns, 5), 0.2);
  const SubdivisionStencil stencil = BuildLoopSubdivision(grid, 1);
  const Mesh fine = ApplySubdivision(stencil, grid.vertices);
  auto at = [&](int x, int y) -> Eigen::Vector3d {
    return grid.vertices.col(GridId(x, y, columns));
  };

  // Valence 6: 5/8 of itself, 1/16 of each of (+-1, 0), (0, +-1), (1, 1), (-1, -1).
  const Eigen::Vector3d ring_sum = at(3, 2) + at(1, 2) + at(2, 3) + at(2, 1) + at(3, 3) + at(1, 1);
  const Eigen::Vector3d expected_vertex = 5.0 / 8.0 * at(2, 2) + ring_sum / 16.0;
  EXPECT_LT((fine.vertices.col(GridId(2, 2, columns)) - expected_vertex).norm(), 1e-12);

  // Edge (2, 2)-(3, 2) lies between triangles whose third corners are (3, 3) and (2, 1).
  const Eigen::Vector3d expected_edge =
      3.0 / 8.0 * (at(2, 2) + at(3, 2)) + 1.0 / 8.0 * (at(3, 3) + at(2, 1));
  const int edge_point = EdgePoint(stencil, GridId(2, 2, columns), GridId(3, 2, columns));
  EXPECT_LT((fine.vertices.col(edge_point) - expected_edge).norm(), 1e-12);
}

TEST(SubdivisionTest, BoundaryFollowsTheCreaseRules) {
  const int columns = 5;
  Mesh grid = Jittered(GridMesh(columns, 4), 0.2);
  // Keep the bottom row on the line y = z = 0, unevenly spaced along x.
  for (int x = 0; x < columns; ++x) grid.vertices.col(GridId(x, 0, columns)).tail<2>().setZero();
  const SubdivisionStencil stencil = BuildLoopSubdivision(grid, 1);
  const Mesh fine = ApplySubdivision(stencil, grid.vertices);
  auto at = [&](int x, int y) -> Eigen::Vector3d {
    return grid.vertices.col(GridId(x, y, columns));
  };

  const Eigen::Vector3d expected_vertex = 0.75 * at(2, 0) + 0.125 * (at(1, 0) + at(3, 0));
  EXPECT_LT((fine.vertices.col(GridId(2, 0, columns)) - expected_vertex).norm(), 1e-12);
  const int edge_point = EdgePoint(stencil, GridId(2, 0, columns), GridId(3, 0, columns));
  EXPECT_LT((fine.vertices.col(edge_point) - 0.5 * (at(2, 0) + at(3, 0))).norm(), 1e-12);

  // After two levels, the fine vertices computed from the bottom row alone stay on its line.
  // The grid's corners are boundary vertices too, so they take 1/8 of their upper neighbour and
  // leave the line; what depends on them does as well. That leaves, along the 17 fine boundary
  // vertices of the bottom, the vertex points from x = 1 to 3 (5) and the edge points between
  // x = 0.5 and 3.5 (6).
  const SubdivisionStencil two = BuildLoopSubdivision(grid, 2);
  const Mesh fine_two = ApplySubdivision(two, grid.vertices);
  const Eigen::SparseMatrix<double, Eigen::RowMajor> rows = two.matrix;
  int from_bottom_row = 0;
  for (int v = 0; v < rows.rows(); ++v) {
    bool bottom_only = true;
    for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(rows, v); it; ++it) {
      bottom_only = bottom_only && it.col() < columns;
    }
    if (!bottom_only) continue;
    ++from_bottom_row;
    EXPECT_LT(fine_two.vertices.col(v).tail<2>().norm(), 1e-12) << "fine vertex " << v;
  }
  EXPECT_EQ(from_bottom_row, 11);
}

TEST(SubdivisionTest, TubeHemsStayInTheirPlanes) {
  const Mesh tube = TubeMesh(12, 4, 0.4, 0.6);
  const Mesh fine = ApplySubdivision(BuildLoopSubdivision(tube, 2), tube.vertices);
  const MeshEdges edges = BuildMeshEdges(fine.faces);
  int boundary_edges = 0;
  for (int e = 0; e < edges.num_edges(); ++e) {
    if (!edges.IsBoundary(e)) continue;
    ++boundary_edges;
    for (int end = 0; end < 2; ++end) {
      const double z = fine.vertices(2, edges.vertices(end, e));
      EXPECT_TRUE(std::abs(z) < 1e-12 || std::abs(z - 0.6) < 1e-12) << "z = " << z;
    }
  }
  EXPECT_EQ(boundary_edges, 2 * 12 * 4);  // Two hems, each edge split twice.
}

TEST(SubdivisionTest, PlanarMeshStaysPlanar) {
  for (const Mesh& mesh : {GridMesh(6, 5), Fan(5)}) {
    Mesh planar = Jittered(mesh, 0.3);
    const Eigen::Vector3d normal = Eigen::Vector3d(0.3, -0.5, 1.0).normalized();
    // Project the jittered points onto the plane normal . x = 0.7.
    for (int v = 0; v < planar.num_vertices(); ++v) {
      const Eigen::Vector3d p = planar.vertices.col(v);
      planar.vertices.col(v) = p - (normal.dot(p) - 0.7) * normal;
    }
    for (SubdivisionScheme scheme : {SubdivisionScheme::kLoop, SubdivisionScheme::kButterfly}) {
      const Mesh fine = ApplySubdivision(BuildSubdivision(scheme, planar, 2), planar.vertices);
      const Eigen::ArrayXd heights = (normal.transpose() * fine.vertices).array() - 0.7;
      EXPECT_LT(heights.abs().maxCoeff(), 1e-12) << EnumToString(scheme);
    }
  }
}

// A geodesic sphere: the icosahedron's triangles split `levels` times, each new vertex the
// normalised midpoint of its parents, found through the stencil's level_edges.
Mesh GeodesicSphere(int levels) {
  const Mesh ico = Icosahedron();
  const SubdivisionStencil split = BuildLoopSubdivision(ico, levels);
  Mesh sphere;
  sphere.faces = split.faces;
  sphere.vertices.resize(3, split.num_fine_vertices());
  sphere.vertices.leftCols(12) = ico.vertices;
  int next = 12;
  for (const Eigen::Matrix2Xi& edges : split.level_edges) {
    for (int e = 0; e < edges.cols(); ++e) {
      sphere.vertices.col(next + e) =
          (sphere.vertices.col(edges(0, e)) + sphere.vertices.col(edges(1, e))).normalized();
    }
    next += static_cast<int>(edges.cols());
  }
  return sphere;
}

// Largest distance of the twice Loop-subdivided surface from the unit sphere.
double LoopDeviationFromSphere(const Mesh& sphere) {
  const Mesh fine = ApplySubdivision(BuildLoopSubdivision(sphere, 2), sphere.vertices);
  return (fine.vertices.colwise().norm().array() - 1.0).abs().maxCoeff();
}

TEST(SubdivisionTest, SubdividedSphereStaysCloseToTheSphere) {
  const Mesh coarse = GeodesicSphere(2);
  ASSERT_EQ(coarse.num_vertices(), 162);
  const Mesh fine = ApplySubdivision(BuildLoopSubdivision(coarse, 2), coarse.vertices);
  const Eigen::ArrayXd radii = fine.vertices.colwise().norm().transpose().array();
  // Loop's surface lies slightly inside the control polygon of a convex surface.
  EXPECT_LT(radii.maxCoeff(), 1.0);
  EXPECT_GT(radii.minCoeff(), 0.97);
  EXPECT_LT(radii.maxCoeff() - radii.minCoeff(), 0.01);
  // The shrink is second order in the edge length: halving the edges divides it by about 4.
  EXPECT_LT(LoopDeviationFromSphere(GeodesicSphere(3)), 0.3 * LoopDeviationFromSphere(coarse));
}

TEST(SubdivisionTest, LevelsComposeAsRepeatedSubdivision) {
  const Mesh tube = Jittered(TubeMesh(5, 3), 0.1);
  const SubdivisionStencil once = BuildLoopSubdivision(tube, 1);
  const Mesh first = ApplySubdivision(once, tube.vertices);
  const Mesh twice = ApplySubdivision(BuildLoopSubdivision(first, 1), first.vertices);
  const Mesh direct = ApplySubdivision(BuildLoopSubdivision(tube, 2), tube.vertices);
  EXPECT_EQ(direct.faces, twice.faces);
  EXPECT_LT((direct.vertices - twice.vertices).cwiseAbs().maxCoeff(), 1e-12);
}

// For a mesh around the origin whose faces all see it from inside (a convex closed surface).
void ExpectEveryTriangleFacesOutwards(const Mesh& mesh) {
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const Eigen::Vector3d a = mesh.vertices.col(mesh.faces(0, f));
    const Eigen::Vector3d b = mesh.vertices.col(mesh.faces(1, f));
    const Eigen::Vector3d c = mesh.vertices.col(mesh.faces(2, f));
    EXPECT_GT((b - a).cross(c - a).dot(a + b + c), 0.0) << "triangle " << f << " faces inwards";
  }
}

TEST(SubdivisionTest, FineFacesKeepTheOrientation) {
  const Mesh ico = Icosahedron();
  const Mesh fine = ApplySubdivision(BuildLoopSubdivision(ico, 2), ico.vertices);
  ExpectEveryTriangleFacesOutwards(fine);
}

TEST(SubdivisionTest, LinearSubdivisionSamplesTheCoarseTrianglesAsGiven) {
  const Mesh ico = Jittered(Icosahedron(), 0.1);
  const SubdivisionStencil stencil = BuildLoopSubdivision(ico, 2);
  const Mesh linear = ApplyLinearSubdivision(stencil, ico.vertices);
  const Mesh loop = ApplySubdivision(stencil, ico.vertices);
  EXPECT_EQ(linear.faces, loop.faces);
  ASSERT_EQ(linear.num_vertices(), loop.num_vertices());
  // The coarse vertices stay where they are (Loop moves them) ...
  EXPECT_EQ(linear.vertices.leftCols(12), ico.vertices);
  EXPECT_GT((loop.vertices.leftCols(12) - ico.vertices).norm(), 0.1);
  // ... and every fine triangle lies in the plane of its coarse triangle: the fine face f comes
  // from coarse face f / 16 after two levels.
  for (int f = 0; f < linear.faces.cols(); ++f) {
    const Eigen::Vector3i corners = ico.faces.col(f / 16);
    const Eigen::Vector3d a = ico.vertices.col(corners[0]);
    const Eigen::Vector3d normal =
        (ico.vertices.col(corners[1]) - a).cross(ico.vertices.col(corners[2]) - a).normalized();
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(normal.dot(linear.vertices.col(linear.faces(c, f)) - a), 0.0, 1e-12)
          << "fine face " << f;
    }
  }
  // The point between coarse vertices 0 and its neighbour is their midpoint.
  const SubdivisionStencil one = BuildLoopSubdivision(ico, 1);
  const int b = ico.faces(1, 0), a = ico.faces(0, 0);
  EXPECT_TRUE(ApplyLinearSubdivision(one, ico.vertices)
                  .vertices.col(EdgePoint(one, a, b))
                  .isApprox(0.5 * (ico.vertices.col(a) + ico.vertices.col(b))));
  EXPECT_THROW(ApplyLinearSubdivision(one, ico.vertices.leftCols(11)), Error);
}

TEST(SubdivisionTest, MaskKeepsEdgePointsWhoseParentsAreBothIn) {
  const Mesh tube = TubeMesh(6, 3);
  const SubdivisionStencil stencil = BuildLoopSubdivision(tube, 2);
  std::vector<bool> mask(tube.num_vertices(), false);
  for (int v = 6; v < 18; ++v) mask[v] = true;  // The upper two rings.
  const std::vector<bool> fine_mask = SubdivideVertexMask(stencil, mask);
  ASSERT_EQ(static_cast<int>(fine_mask.size()), stencil.num_fine_vertices());
  const Mesh fine = ApplySubdivision(stencil, tube.vertices);
  // Exactly the fine vertices at or above the middle ring's height, up to rounding.
  for (int v = 0; v < stencil.num_fine_vertices(); ++v) {
    EXPECT_EQ(fine_mask[v], fine.vertices(2, v) > 0.5 - 1e-9) << "fine vertex " << v;
  }
  EXPECT_THROW(SubdivideVertexMask(stencil, std::vector<bool>(3, true)), Error);
}

TEST(SubdivisionTest, RefusesNonManifoldEdgesAndWrongFrames) {
  Mesh fan;  // Three triangles on the edge (0, 1).
  fan.vertices = Eigen::Matrix3Xd::Random(3, 5);
  fan.faces.resize(3, 3);
  fan.faces << 0, 0, 0, 1, 1, 1, 2, 3, 4;
  try {
    BuildLoopSubdivision(fan, 1, "fan.ply");
    FAIL() << "no error";
  } catch (const Error& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("fan.ply"), std::string::npos) << message;
    EXPECT_NE(message.find("edge (0, 1) is shared by 3 triangles"), std::string::npos) << message;
    EXPECT_NE(message.find("non-manifold"), std::string::npos) << message;
  }
  EXPECT_THROW(BuildLoopSubdivision(Icosahedron(), -1), Error);
  // Midpoints need no rule across the edge: the linear scheme splits the fan.
  const SubdivisionStencil split = BuildLinearSubdivision(fan, 1, "fan.ply");
  EXPECT_EQ(split.faces.cols(), 12);
  EXPECT_EQ(split.num_fine_vertices(), 5 + 7);

  const SubdivisionStencil stencil = BuildLoopSubdivision(Icosahedron(), 1);
  try {
    ApplySubdivision(stencil, Eigen::Matrix3Xd::Zero(3, 11), "frame_0007.ply");
    FAIL() << "no error";
  } catch (const Error& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("frame_0007.ply"), std::string::npos) << message;
    EXPECT_NE(message.find("11 vertices but the subdivision was built for 12"), std::string::npos)
        << message;
  }
}

// The neighbours of vertex v of a convex closed mesh in order around it (by angle about the
// direction to v), starting at `first`: the order Zorin's weights run in.
std::vector<int> RingByAngle(const Mesh& mesh, int v, int first) {
  std::vector<int> ring;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    for (int corner = 0; corner < 3; ++corner) {
      if (mesh.faces(corner, f) == v) ring.push_back(mesh.faces((corner + 1) % 3, f));
    }
  }
  const Eigen::Vector3d axis = mesh.vertices.col(v).normalized();
  const Eigen::Vector3d x = (mesh.vertices.col(first) - mesh.vertices.col(v)).normalized();
  const Eigen::Vector3d y = axis.cross(x);
  auto angle = [&](int u) {
    const Eigen::Vector3d d = mesh.vertices.col(u) - mesh.vertices.col(v);
    const double a = std::atan2(d.dot(y), d.dot(x));
    return a < -1e-9 ? a + 2.0 * M_PI : a;
  };
  std::sort(ring.begin(), ring.end(), [&](int a, int b) { return angle(a) < angle(b); });
  return ring;
}

double ZorinWeight(int j, int valence) {
  const double angle = 2.0 * M_PI * j / valence;
  return (0.25 + std::cos(angle) + 0.5 * std::cos(2.0 * angle)) / valence;
}

// 3/4 of v and Zorin's weights of its ring, from the edge's other end on.
Eigen::Vector3d ZorinStencil(const Mesh& mesh, int v, int other) {
  const std::vector<int> ring = RingByAngle(mesh, v, other);
  const int valence = static_cast<int>(ring.size());
  Eigen::Vector3d point = 0.75 * mesh.vertices.col(v);
  for (int j = 0; j < valence; ++j) point += ZorinWeight(j, valence) * mesh.vertices.col(ring[j]);
  return point;
}

TEST(ButterflySubdivisionTest, SchemesHaveTheirNames) {
  EXPECT_EQ(EnumToString(SubdivisionScheme::kLoop), "loop");
  EXPECT_EQ(EnumToString(SubdivisionScheme::kButterfly), "butterfly");
  EXPECT_THROW(BuildSubdivision(static_cast<SubdivisionScheme>(7), Icosahedron(), 1), Error);
}

TEST(ButterflySubdivisionTest, KeepsEveryCoarseVertexAndRowsSumToOne) {
  for (const Mesh& mesh :
       {Icosahedron(), TriangulatedCube(), TubeMesh(7, 5), GridMesh(4, 3), Fan(3), Fan(7)}) {
    for (int levels : {1, 2}) {
      const Mesh jittered = Jittered(mesh, 0.05);
      const SubdivisionStencil stencil = BuildButterflySubdivision(jittered, levels);
      // The same topology as Loop's.
      const SubdivisionStencil loop = BuildLoopSubdivision(jittered, levels);
      EXPECT_EQ(stencil.faces, loop.faces);
      ASSERT_EQ(stencil.num_fine_vertices(), loop.num_fine_vertices());
      for (int v = 0; v < mesh.num_vertices(); ++v) {
        const std::vector<std::pair<int, double>> identity = {{v, 1.0}};
        EXPECT_EQ(Row(stencil, v), identity) << "coarse vertex " << v;
      }
      const Eigen::VectorXd sums = stencil.matrix * Eigen::VectorXd::Ones(mesh.num_vertices());
      EXPECT_LT((sums.array() - 1.0).abs().maxCoeff(), 1e-12);
      const Mesh fine = ApplySubdivision(stencil, jittered.vertices);
      EXPECT_TRUE(
          (fine.vertices.leftCols(mesh.num_vertices()).array() == jittered.vertices.array()).all());
      EXPECT_TRUE(fine.vertices.allFinite());
    }
  }
}

TEST(ButterflySubdivisionTest, RegularInteriorEdgeTakesTheEightPointStencil) {
  const int columns = 5;
  const Mesh grid = Jittered(GridMesh(columns, 5), 0.2);
  const SubdivisionStencil stencil = BuildButterflySubdivision(grid, 1);
  const int a = GridId(2, 2, columns), b = GridId(3, 2, columns);
  const int edge_point = EdgePoint(stencil, a, b);
  // Opposite the edge: (3, 3) and (2, 1); the wings across the other sides of its two triangles:
  // (4, 3), (2, 3), (3, 1) and (1, 1).
  std::vector<std::pair<int, double>> expected = {{a, 0.5},
                                                  {b, 0.5},
                                                  {GridId(3, 3, columns), 1.0 / 8.0},
                                                  {GridId(2, 1, columns), 1.0 / 8.0},
                                                  {GridId(4, 3, columns), -1.0 / 16.0},
                                                  {GridId(2, 3, columns), -1.0 / 16.0},
                                                  {GridId(3, 1, columns), -1.0 / 16.0},
                                                  {GridId(1, 1, columns), -1.0 / 16.0}};
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(Row(stencil, edge_point), expected);

  // The butterfly reproduces cubics: on a regular grid it puts a point of the graph of a cubic
  // polynomial on the graph (Loop's 3/8, 1/8 would not).
  Mesh graph = GridMesh(columns, 5);
  auto height = [](double x, double y) { return 0.1 * x * x * x - 0.3 * x * y * y + 0.2 * y; };
  for (int v = 0; v < graph.num_vertices(); ++v) {
    graph.vertices(2, v) = height(graph.vertices(0, v), graph.vertices(1, v));
  }
  const Eigen::Vector3d point = ApplySubdivision(stencil, graph.vertices).vertices.col(edge_point);
  EXPECT_NEAR(point.x(), 2.5, 1e-12);
  EXPECT_NEAR(point.y(), 2.0, 1e-12);
  EXPECT_NEAR(point.z(), height(2.5, 2.0), 1e-12);
}

TEST(ButterflySubdivisionTest, BoundaryEdgeTakesTheFourPointCurveRule) {
  const int columns = 5;
  const Mesh grid = Jittered(GridMesh(columns, 4), 0.2);
  const SubdivisionStencil stencil = BuildButterflySubdivision(grid, 1);
  const int edge_point = EdgePoint(stencil, GridId(2, 0, columns), GridId(3, 0, columns));
  std::vector<std::pair<int, double>> expected = {{GridId(1, 0, columns), -1.0 / 16.0},
                                                  {GridId(2, 0, columns), 9.0 / 16.0},
                                                  {GridId(3, 0, columns), 9.0 / 16.0},
                                                  {GridId(4, 0, columns), -1.0 / 16.0}};
  EXPECT_EQ(Row(stencil, edge_point), expected);

  // A closed hem stays a curve of its own: after two levels every fine vertex on the tube's
  // lower hem lies in its plane, and the hem's vertices stay on the circle.
  const Mesh tube = TubeMesh(12, 4, 0.4, 0.6);
  const Mesh fine = ApplySubdivision(BuildButterflySubdivision(tube, 2), tube.vertices);
  const MeshEdges edges = BuildMeshEdges(fine.faces);
  for (int e = 0; e < edges.num_edges(); ++e) {
    if (!edges.IsBoundary(e)) continue;
    for (int end = 0; end < 2; ++end) {
      const Eigen::Vector3d p = fine.vertices.col(edges.vertices(end, e));
      EXPECT_TRUE(std::abs(p.z()) < 1e-12 || std::abs(p.z() - 0.6) < 1e-12) << "z = " << p.z();
      EXPECT_NEAR(p.head<2>().norm(), 0.4, 2e-3);  // The 4-point curve rounds the 12-gon.
    }
  }
}

TEST(ButterflySubdivisionTest, ExtraordinaryVertexTakesZorinsWeights) {
  const std::vector<std::vector<double>> small = {{5.0 / 12.0, -1.0 / 12.0, -1.0 / 12.0},
                                                  {3.0 / 8.0, 0.0, -1.0 / 8.0, 0.0}};
  for (int valence : {3, 4, 5, 7, 9}) {
    const Mesh fan = Fan(valence);
    const SubdivisionStencil stencil = BuildButterflySubdivision(fan, 1);
    // The rim vertices are on the boundary: the edge from the centre to rim vertex 1 takes the
    // centre's stencil alone, its weights running round the rim from vertex 1 (either way).
    const int edge_point = EdgePoint(stencil, 0, 1);
    EXPECT_DOUBLE_EQ(stencil.matrix.coeff(edge_point, 0), 0.75) << "valence " << valence;
    for (int j = 0; j < valence; ++j) {
      const double weight = valence < 5 ? small[valence - 3][j] : ZorinWeight(j, valence);
      const int forward = 1 + j, backward = 1 + (valence - j) % valence;
      EXPECT_NEAR(stencil.matrix.coeff(edge_point, forward), weight, 1e-15)
          << "valence " << valence << ", j " << j;
      EXPECT_NEAR(stencil.matrix.coeff(edge_point, backward), weight, 1e-15)
          << "valence " << valence << ", j " << j;
    }
  }
  EXPECT_NEAR(ZorinWeight(0, 5), 0.35, 1e-15);  // (1/4 + 1 + 1/2) / 5.

  // Every vertex of the icosahedron has valence 5: each edge point is the mean of its two ends'
  // stencils, and by symmetry all lie on the rays through the edges' midpoints at one radius.
  const Mesh ico = Icosahedron();
  const SubdivisionStencil stencil = BuildButterflySubdivision(ico, 1);
  const Mesh fine = ApplySubdivision(stencil, ico.vertices);
  const Eigen::Matrix2Xi& edges = stencil.level_edges[0];
  const double radius = fine.vertices.col(12).norm();
  for (int e = 0; e < edges.cols(); ++e) {
    const int a = edges(0, e), b = edges(1, e);
    const Eigen::Vector3d expected = 0.5 * (ZorinStencil(ico, a, b) + ZorinStencil(ico, b, a));
    EXPECT_LT((fine.vertices.col(12 + e) - expected).norm(), 1e-12) << "edge " << a << "-" << b;
    const Eigen::Vector3d mid = ico.vertices.col(a) + ico.vertices.col(b);
    EXPECT_LT(fine.vertices.col(12 + e).cross(mid).norm(), 1e-12);
    EXPECT_NEAR(fine.vertices.col(12 + e).norm(), radius, 1e-12);
  }
  // Interpolating, it bulges past the edges' midpoints towards the sphere.
  EXPECT_GT(radius, (ico.vertices.col(0) + ico.vertices.col(11)).norm() / 2.0);
}

TEST(ButterflySubdivisionTest, ClosedMeshesSubdivideFacingOutwards) {
  for (const Mesh& mesh : {Icosahedron(), TriangulatedCube()}) {
    const Mesh fine = ApplySubdivision(BuildButterflySubdivision(mesh, 2), mesh.vertices);
    ASSERT_EQ(fine.num_faces(), 16 * mesh.num_faces());
    EXPECT_EQ(BuildMeshEdges(fine.faces).num_edges(), 3 * fine.num_faces() / 2);  // Closed.
    ExpectEveryTriangleFacesOutwards(fine);
  }
}

TEST(ButterflySubdivisionTest, RefusesWhatLoopRefuses) {
  Mesh fan;  // Three triangles on the edge (0, 1).
  fan.vertices = Eigen::Matrix3Xd::Random(3, 5);
  fan.faces.resize(3, 3);
  fan.faces << 0, 0, 0, 1, 1, 1, 2, 3, 4;
  ExpectErrorMentions(
      [&] { BuildButterflySubdivision(fan, 1, "fan.ply"); },
      {"fan.ply", "edge (0, 1) is shared by 3 triangles", "non-manifold", "butterfly subdivision"});
  EXPECT_THROW(BuildButterflySubdivision(Icosahedron(), -1), Error);
  Mesh out_of_range = Icosahedron();
  out_of_range.faces(1, 3) = 12;
  ExpectErrorMentions([&] { BuildButterflySubdivision(out_of_range, 1, "bad.ply"); }, {"bad.ply"});
}

}  // namespace
}  // namespace finecap
