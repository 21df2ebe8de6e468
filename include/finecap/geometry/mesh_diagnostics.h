// Finds degenerate geometry that the refinement cannot handle well or that hints at a broken
// export: collapsed triangles, vertices in no triangle, edges shared by three or more triangles,
// triangles listed twice, and neighbouring triangles whose orientations disagree. The result
// carries counts, a few example ids and a one-line description, so a caller can refuse the mesh
// or warn with a message that says what is wrong and where to look.
#ifndef FINECAP_GEOMETRY_MESH_DIAGNOSTICS_H_
#define FINECAP_GEOMETRY_MESH_DIAGNOSTICS_H_

#include <string>
#include <vector>

#include <Eigen/Core>

#include "finecap/geometry/mesh.h"

namespace finecap {

struct MeshDiagnosticsOptions {
  // A triangle counts as degenerate (near-zero area) when area <= relative_area_tolerance *
  // (longest side)^2. The ratio is scale-free and about half the sine of the triangle's smallest
  // angle for slivers (an equilateral triangle has 0.433), so it catches both collapsed vertices
  // and three nearly collinear ones. Must be in [0, 0.433). Default 1e-10.
  double relative_area_tolerance = 1e-10;
  // How many example ids to keep per kind of problem. Must be >= 0. Default 5.
  int max_examples = 5;

  void Check() const;
};

struct MeshDiagnostics {
  // Triangles with (near-)zero area, including those that repeat a vertex or have a non-finite
  // corner.
  int num_degenerate_faces = 0;
  std::vector<int> degenerate_face_examples;
  // Vertices that no triangle uses.
  int num_isolated_vertices = 0;
  std::vector<int> isolated_vertex_examples;
  // Edges in three or more triangles, as (smaller, larger) vertex ids.
  int num_non_manifold_edges = 0;
  std::vector<Eigen::Vector2i> non_manifold_edge_examples;
  // Triangles with the same three vertices as an earlier triangle (in any order or orientation);
  // the examples are the later copies.
  int num_duplicate_faces = 0;
  std::vector<int> duplicate_face_examples;
  // Edges between two triangles that traverse it in the same direction, i.e. whose normals point
  // to opposite sides; as (smaller, larger) vertex ids.
  int num_inconsistently_oriented_edges = 0;
  std::vector<Eigen::Vector2i> inconsistently_oriented_edge_examples;

  bool HasProblems() const;
  // One line for a log or an error message, e.g. "2 degenerate triangles (e.g. 4, 9); 1
  // non-manifold edge (e.g. 3-7)", or "no degenerate geometry" for a clean mesh.
  std::string Describe() const;
};

// Examines `mesh`. Throws Error(where, ...) when options.Check() fails or a triangle refers to a
// vertex that does not exist (the mesh is then broken, not merely degenerate).
MeshDiagnostics DiagnoseMesh(const Mesh& mesh, const MeshDiagnosticsOptions& options = {},
                             const std::string& where = "mesh");

}  // namespace finecap

#endif  // FINECAP_GEOMETRY_MESH_DIAGNOSTICS_H_
