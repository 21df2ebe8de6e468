#include "finecap/geometry/mesh_diagnostics.h"

#include <algorithm>
#include <array>
#include <sstream>
#include <utility>

#include <Eigen/Geometry>

#include "finecap/geometry/mesh_edges.h"
#include "finecap/util/error.h"

namespace finecap {
namespace {

// Counts one more problem and keeps its id while there is room for examples.
template <typename Id>
void Record(const Id& id, int max_examples, int* count, std::vector<Id>* examples) {
  ++*count;
  if (static_cast<int>(examples->size()) < max_examples) examples->push_back(id);
}

void RequireVerticesExist(const Mesh& mesh, const std::string& where) {
  for (int f = 0; f < mesh.num_faces(); ++f) {
    if (mesh.faces.col(f).minCoeff() >= 0 && mesh.faces.col(f).maxCoeff() < mesh.num_vertices()) {
      continue;
    }
    throw Error(where, "triangle " + std::to_string(f) + " refers to a vertex that does not exist");
  }
}

bool IsDegenerate(const Mesh& mesh, int f, double relative_area_tolerance) {
  const Eigen::Vector3d a = mesh.vertices.col(mesh.faces(0, f));
  const Eigen::Vector3d b = mesh.vertices.col(mesh.faces(1, f));
  const Eigen::Vector3d c = mesh.vertices.col(mesh.faces(2, f));
  const double area = 0.5 * (b - a).cross(c - a).norm();
  const double longest_squared =
      std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
  // Written so that a NaN area (a non-finite corner) also counts as degenerate.
  return !(area > relative_area_tolerance * longest_squared);
}

void FindDegenerateFaces(const Mesh& mesh, const MeshDiagnosticsOptions& options,
                         MeshDiagnostics* result) {
  for (int f = 0; f < mesh.num_faces(); ++f) {
    if (IsDegenerate(mesh, f, options.relative_area_tolerance)) {
      Record(f, options.max_examples, &result->num_degenerate_faces,
             &result->degenerate_face_examples);
    }
  }
}

void FindIsolatedVertices(const Mesh& mesh, int max_examples, MeshDiagnostics* result) {
  std::vector<bool> used(mesh.num_vertices(), false);
  for (int f = 0; f < mesh.num_faces(); ++f) {
    for (int corner = 0; corner < 3; ++corner) used[mesh.faces(corner, f)] = true;
  }
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    if (!used[v]) {
      Record(v, max_examples, &result->num_isolated_vertices, &result->isolated_vertex_examples);
    }
  }
}

void FindDuplicateFaces(const Mesh& mesh, int max_examples, MeshDiagnostics* result) {
  std::vector<std::pair<std::array<int, 3>, int>> keyed(mesh.num_faces());
  for (int f = 0; f < mesh.num_faces(); ++f) {
    std::array<int, 3> key = {mesh.faces(0, f), mesh.faces(1, f), mesh.faces(2, f)};
    std::sort(key.begin(), key.end());
    keyed[f] = {key, f};
  }
  std::sort(keyed.begin(), keyed.end());
  std::vector<int> later_copies;
  for (size_t i = 1; i < keyed.size(); ++i) {
    if (keyed[i].first == keyed[i - 1].first) later_copies.push_back(keyed[i].second);
  }
  std::sort(later_copies.begin(), later_copies.end());
  for (const int f : later_copies) {
    Record(f, max_examples, &result->num_duplicate_faces, &result->duplicate_face_examples);
  }
}

// Two triangles agree in orientation when they traverse their shared edge in opposite directions.
bool SidesAgree(const Mesh& mesh, int side_a, int side_b) {
  const int start_a = mesh.faces(SideCorner(side_a), SideFace(side_a));
  const int start_b = mesh.faces(SideCorner(side_b), SideFace(side_b));
  return start_a != start_b;
}

void FindEdgeProblems(const Mesh& mesh, int max_examples, MeshDiagnostics* result) {
  const MeshEdges edges = BuildMeshEdges(mesh.faces);
  for (int e = 0; e < edges.num_edges(); ++e) {
    const Eigen::Vector2i endpoints = edges.vertices.col(e);
    if (edges.NumSides(e) > 2) {
      Record(endpoints, max_examples, &result->num_non_manifold_edges,
             &result->non_manifold_edge_examples);
    } else if (edges.NumSides(e) == 2) {
      const int first = edges.side_offsets[e];
      if (!SidesAgree(mesh, edges.sides[first], edges.sides[first + 1])) {
        Record(endpoints, max_examples, &result->num_inconsistently_oriented_edges,
               &result->inconsistently_oriented_edge_examples);
      }
    }
  }
}

std::string FormatId(int id) { return std::to_string(id); }
std::string FormatId(const Eigen::Vector2i& edge) {
  return std::to_string(edge(0)) + "-" + std::to_string(edge(1));
}

// "2 degenerate triangles (e.g. 4, 9)"; nothing when count is 0.
template <typename Id>
void DescribeProblem(int count, const std::string& singular, const std::string& plural,
                     const std::vector<Id>& examples, std::vector<std::string>* parts) {
  if (count == 0) return;
  std::ostringstream text;
  text << count << ' ' << (count == 1 ? singular : plural);
  for (size_t i = 0; i < examples.size(); ++i) {
    text << (i == 0 ? " (e.g. " : ", ") << FormatId(examples[i]);
  }
  if (!examples.empty()) text << ')';
  parts->push_back(text.str());
}

}  // namespace

void MeshDiagnosticsOptions::Check() const {
  Require(relative_area_tolerance >= 0.0 && relative_area_tolerance < 0.433,
          "mesh diagnostics options",
          "relative_area_tolerance must be in [0, 0.433), got " +
              std::to_string(relative_area_tolerance));
  Require(max_examples >= 0, "mesh diagnostics options",
          "max_examples must be at least 0, got " + std::to_string(max_examples));
}

bool MeshDiagnostics::HasProblems() const {
  return num_degenerate_faces > 0 || num_isolated_vertices > 0 || num_non_manifold_edges > 0 ||
         num_duplicate_faces > 0 || num_inconsistently_oriented_edges > 0;
}

std::string MeshDiagnostics::Describe() const {
  std::vector<std::string> parts;
  DescribeProblem(num_degenerate_faces, "degenerate triangle", "degenerate triangles",
                  degenerate_face_examples, &parts);
  DescribeProblem(num_isolated_vertices, "isolated vertex", "isolated vertices",
                  isolated_vertex_examples, &parts);
  DescribeProblem(num_non_manifold_edges, "non-manifold edge", "non-manifold edges",
                  non_manifold_edge_examples, &parts);
  DescribeProblem(num_duplicate_faces, "duplicate triangle", "duplicate triangles",
                  duplicate_face_examples, &parts);
  DescribeProblem(num_inconsistently_oriented_edges, "inconsistently oriented edge",
                  "inconsistently oriented edges", inconsistently_oriented_edge_examples, &parts);
  if (parts.empty()) return "no degenerate geometry";
  std::string line = parts[0];
  for (size_t i = 1; i < parts.size(); ++i) line += "; " + parts[i];
  return line;
}

MeshDiagnostics DiagnoseMesh(const Mesh& mesh, const MeshDiagnosticsOptions& options,
                             const std::string& where) {
  options.Check();
  RequireVerticesExist(mesh, where);
  MeshDiagnostics result;
  FindDegenerateFaces(mesh, options, &result);
  FindIsolatedVertices(mesh, options.max_examples, &result);
  FindDuplicateFaces(mesh, options.max_examples, &result);
  FindEdgeProblems(mesh, options.max_examples, &result);
  return result;
}

}  // namespace finecap
