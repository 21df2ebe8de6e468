#include "finecap/geometry/mesh_diagnostics.h"

#include <gtest/gtest.h>

#include "finecap/util/error.h"
#include "test_meshes.h"

namespace finecap {
namespace {

using testing_meshes::GridMesh;
using testing_meshes::Icosahedron;

Mesh WithFaces(Mesh mesh, const std::vector<Eigen::Vector3i>& extra_faces) {
  const int old = mesh.num_faces();
  mesh.faces.conservativeResize(3, old + static_cast<int>(extra_faces.size()));
  for (size_t i = 0; i < extra_faces.size(); ++i) mesh.faces.col(old + i) = extra_faces[i];
  return mesh;
}

TEST(MeshDiagnosticsTest, CleanMeshesHaveNoProblems) {
  for (const Mesh& mesh : {Icosahedron(), GridMesh(4, 3)}) {
    const MeshDiagnostics diagnostics = DiagnoseMesh(mesh);
    EXPECT_FALSE(diagnostics.HasProblems()) << diagnostics.Describe();
    EXPECT_EQ(diagnostics.Describe(), "no degenerate geometry");
  }
}

TEST(MeshDiagnosticsTest, FindsZeroAndNearZeroAreaTriangles) {
  Mesh mesh = GridMesh(3, 3);                   // 8 triangles, vertex (x, y) at 3 * y + x.
  mesh.vertices.col(4) = mesh.vertices.col(0);  // Collapses triangles 0 and 1 (both use 0 and 4).
  // Triangle 7 is (4, 8, 7): move 7 onto the segment 4-8, up to 1e-12 (a sliver, not exact).
  mesh.vertices.col(7) = 0.5 * (mesh.vertices.col(4) + mesh.vertices.col(8));
  mesh.vertices(2, 7) += 1e-12;
  const MeshDiagnostics diagnostics = DiagnoseMesh(mesh);
  EXPECT_EQ(diagnostics.num_degenerate_faces, 3);
  EXPECT_EQ(diagnostics.degenerate_face_examples, (std::vector<int>{0, 1, 7}));
  EXPECT_EQ(diagnostics.Describe(), "3 degenerate triangles (e.g. 0, 1, 7)");

  // A looser tolerance also flags a thin but honest triangle; a tight one keeps the sliver.
  Mesh thin = GridMesh(2, 2);
  thin.vertices(1, 2) = 0.001;  // Triangle 1 is (0, 3, 2): area/longest^2 about 5e-4.
  MeshDiagnosticsOptions loose;
  loose.relative_area_tolerance = 1e-3;
  EXPECT_EQ(DiagnoseMesh(thin, loose).degenerate_face_examples, (std::vector<int>{1}));
  EXPECT_EQ(DiagnoseMesh(thin).num_degenerate_faces, 0);
}

TEST(MeshDiagnosticsTest, CountsTrianglesWithARepeatedOrNonFiniteCorner) {
  Mesh mesh = WithFaces(GridMesh(2, 2), {Eigen::Vector3i(0, 1, 1)});
  mesh.vertices(0, 3) = std::nan("");
  const MeshDiagnostics diagnostics = DiagnoseMesh(mesh);
  // Both grid triangles use vertex 3; the added one repeats vertex 1.
  EXPECT_EQ(diagnostics.num_degenerate_faces, 3);
}

TEST(MeshDiagnosticsTest, FindsIsolatedVertices) {
  Mesh mesh = Icosahedron();
  mesh.vertices.conservativeResize(3, 15);
  mesh.vertices.rightCols(3).setZero();
  MeshDiagnosticsOptions options;
  options.max_examples = 2;
  const MeshDiagnostics diagnostics = DiagnoseMesh(mesh, options);
  EXPECT_EQ(diagnostics.num_isolated_vertices, 3);
  EXPECT_EQ(diagnostics.isolated_vertex_examples, (std::vector<int>{12, 13}));
  EXPECT_EQ(diagnostics.Describe(), "3 isolated vertices (e.g. 12, 13)");
}

TEST(MeshDiagnosticsTest, FindsNonManifoldEdges) {
  Mesh mesh = GridMesh(2, 2);  // Triangles (0, 1, 3) and (0, 3, 2) share the edge 0-3.
  mesh.vertices.conservativeResize(3, 5);
  mesh.vertices.col(4) << 0.5, 0.5, 1.0;
  mesh = WithFaces(mesh, {Eigen::Vector3i(3, 0, 4)});
  const MeshDiagnostics diagnostics = DiagnoseMesh(mesh);
  EXPECT_EQ(diagnostics.num_non_manifold_edges, 1);
  ASSERT_EQ(diagnostics.non_manifold_edge_examples.size(), 1u);
  EXPECT_EQ(diagnostics.non_manifold_edge_examples[0], Eigen::Vector2i(0, 3));
  EXPECT_EQ(diagnostics.num_inconsistently_oriented_edges, 0);
  EXPECT_EQ(diagnostics.Describe(), "1 non-manifold edge (e.g. 0-3)");
}

TEST(MeshDiagnosticsTest, FindsDuplicateTrianglesInAnyOrder) {
  const Mesh mesh = WithFaces(Icosahedron(), {Eigen::Vector3i(5, 0, 11),   // Copy of triangle 0.
                                              Eigen::Vector3i(1, 5, 0)});  // Reversed triangle 1.
  const MeshDiagnostics diagnostics = DiagnoseMesh(mesh);
  EXPECT_EQ(diagnostics.num_duplicate_faces, 2);
  EXPECT_EQ(diagnostics.duplicate_face_examples, (std::vector<int>{20, 21}));
  // Each copy puts a third triangle on its three edges.
  EXPECT_EQ(diagnostics.num_non_manifold_edges, 5);
}

TEST(MeshDiagnosticsTest, FindsInconsistentlyOrientedNeighbours) {
  Mesh mesh = Icosahedron();
  mesh.faces.col(3).reverseInPlace();  // (0, 7, 10) becomes (10, 7, 0).
  const MeshDiagnostics diagnostics = DiagnoseMesh(mesh);
  EXPECT_EQ(diagnostics.num_inconsistently_oriented_edges, 3);
  EXPECT_EQ(diagnostics.inconsistently_oriented_edge_examples,
            (std::vector<Eigen::Vector2i>{Eigen::Vector2i(0, 7), Eigen::Vector2i(0, 10),
                                          Eigen::Vector2i(7, 10)}));
  EXPECT_EQ(diagnostics.Describe(), "3 inconsistently oriented edges (e.g. 0-7, 0-10, 7-10)");
}

TEST(MeshDiagnosticsTest, DescribesSeveralProblemsOnOneLine) {
  Mesh mesh = WithFaces(GridMesh(2, 2), {Eigen::Vector3i(0, 1, 3)});
  mesh.vertices.conservativeResize(3, 5);
  mesh.vertices.col(4).setZero();
  // The copy of (0, 1, 3) makes 0-3 a third triangle's edge, and runs along the boundary edges 0-1
  // and 1-3 in the same direction as the original.
  EXPECT_EQ(DiagnoseMesh(mesh).Describe(),
            "1 isolated vertex (e.g. 4); 1 non-manifold edge (e.g. 0-3); 1 duplicate triangle "
            "(e.g. 2); 2 inconsistently oriented edges (e.g. 0-1, 1-3)");
}

TEST(MeshDiagnosticsTest, RefusesMissingVerticesAndBadOptions) {
  Mesh mesh = GridMesh(2, 2);
  mesh.faces(2, 1) = 9;
  try {
    DiagnoseMesh(mesh, {}, "body_0001.obj");
    FAIL() << "no error";
  } catch (const Error& error) {
    EXPECT_EQ(std::string(error.what()),
              "body_0001.obj: triangle 1 refers to a vertex that does not exist");
  }
  MeshDiagnosticsOptions options;
  options.relative_area_tolerance = -1.0;
  EXPECT_THROW(options.Check(), Error);
  options.relative_area_tolerance = 1e-10;
  options.max_examples = -1;
  EXPECT_THROW(DiagnoseMesh(GridMesh(2, 2), options), Error);
}

}  // namespace
}  // namespace finecap
