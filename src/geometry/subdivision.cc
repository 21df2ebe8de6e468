#include "finecap/geometry/subdivision.h"

#include <cmath>
#include <limits>

#include "finecap/geometry/mesh_edges.h"
#include "finecap/util/error.h"

namespace finecap {
namespace {

using Triplets = std::vector<Eigen::Triplet<double>>;

// Loop's original weight of each neighbour of an interior vertex of valence n.
double LoopBeta(int valence) {
  const double n = valence;
  const double c = 3.0 / 8.0 + 0.25 * std::cos(2.0 * M_PI / n);
  return (5.0 / 8.0 - c * c) / n;
}

void RequireManifoldEdges(const MeshEdges& edges, const std::string& where) {
  for (int e = 0; e < edges.num_edges(); ++e) {
    if (edges.NumSides(e) <= 2) continue;
    throw Error(where, "edge (" + std::to_string(edges.vertices(0, e)) + ", " +
                           std::to_string(edges.vertices(1, e)) + ") is shared by " +
                           std::to_string(edges.NumSides(e)) +
                           " triangles (a non-manifold edge): Loop subdivision needs every edge "
                           "in at most two");
  }
}

// How each vertex is smoothed: the weight on itself and the weight on each neighbour it takes
// (interior vertices take all neighbours, boundary vertices their two boundary neighbours only).
struct VertexRule {
  double self = 1.0;
  double interior_neighbour = 0.0;
  double boundary_neighbour = 0.0;
};

std::vector<VertexRule> VertexRules(int num_vertices, const MeshEdges& edges) {
  std::vector<int> valence(num_vertices, 0), boundary_valence(num_vertices, 0);
  for (int e = 0; e < edges.num_edges(); ++e) {
    for (int end = 0; end < 2; ++end) {
      ++valence[edges.vertices(end, e)];
      if (edges.IsBoundary(e)) ++boundary_valence[edges.vertices(end, e)];
    }
  }
  std::vector<VertexRule> rules(num_vertices);
  for (int v = 0; v < num_vertices; ++v) {
    if (valence[v] > 0 && boundary_valence[v] == 0) {
      const double beta = LoopBeta(valence[v]);
      rules[v] = {1.0 - valence[v] * beta, beta, 0.0};
    } else if (boundary_valence[v] == 2) {
      rules[v] = {0.75, 0.0, 0.125};
    }  // Otherwise isolated or where sheets touch: the default keeps the vertex in place.
  }
  return rules;
}

void AddVertexPoints(const MeshEdges& edges, const std::vector<VertexRule>& rules,
                     Triplets* triplets) {
  for (int v = 0; v < static_cast<int>(rules.size()); ++v)
    triplets->emplace_back(v, v, rules[v].self);
  for (int e = 0; e < edges.num_edges(); ++e) {
    for (int end = 0; end < 2; ++end) {
      const int v = edges.vertices(end, e);
      const int neighbour = edges.vertices(1 - end, e);
      const double weight =
          edges.IsBoundary(e) ? rules[v].boundary_neighbour : rules[v].interior_neighbour;
      if (weight != 0.0) triplets->emplace_back(v, neighbour, weight);
    }
  }
}

void AddEdgePoints(int num_vertices, const Eigen::Matrix3Xi& faces, const MeshEdges& edges,
                   Triplets* triplets) {
  for (int e = 0; e < edges.num_edges(); ++e) {
    const int row = num_vertices + e;
    const bool boundary = edges.IsBoundary(e);
    const double end_weight = boundary ? 0.5 : 3.0 / 8.0;
    triplets->emplace_back(row, edges.vertices(0, e), end_weight);
    triplets->emplace_back(row, edges.vertices(1, e), end_weight);
    if (boundary) continue;
    for (int k = edges.side_offsets[e]; k < edges.side_offsets[e + 1]; ++k) {
      const int side = edges.sides[k];
      const int opposite = faces((SideCorner(side) + 2) % 3, SideFace(side));
      triplets->emplace_back(row, opposite, 1.0 / 8.0);
    }
  }
}

Eigen::Matrix3Xi SplitFaces(int num_vertices, const Eigen::Matrix3Xi& faces,
                            const MeshEdges& edges) {
  Eigen::Matrix3Xi fine(3, 4 * faces.cols());
  for (int f = 0; f < faces.cols(); ++f) {
    const Eigen::Vector3i corner = faces.col(f);
    // mid(c) is the edge point on the side from corner c to corner c + 1.
    const Eigen::Vector3i mid = edges.face_edges.col(f).array() + num_vertices;
    fine.col(4 * f + 0) << corner(0), mid(0), mid(2);
    fine.col(4 * f + 1) << mid(0), corner(1), mid(1);
    fine.col(4 * f + 2) << mid(2), mid(1), corner(2);
    fine.col(4 * f + 3) << mid(0), mid(1), mid(2);
  }
  return fine;
}

struct OneLevel {
  Eigen::SparseMatrix<double> matrix;
  Eigen::Matrix3Xi faces;
  Eigen::Matrix2Xi edges;
};

OneLevel SubdivideOnce(int num_vertices, const Eigen::Matrix3Xi& faces, const std::string& where) {
  const MeshEdges edges = BuildMeshEdges(faces);
  RequireManifoldEdges(edges, where);
  Triplets triplets;
  triplets.reserve(7 * static_cast<size_t>(num_vertices) + 4 * edges.num_edges());
  AddVertexPoints(edges, VertexRules(num_vertices, edges), &triplets);
  AddEdgePoints(num_vertices, faces, edges, &triplets);
  OneLevel level;
  level.matrix.resize(num_vertices + edges.num_edges(), num_vertices);
  level.matrix.setFromTriplets(triplets.begin(), triplets.end());
  level.faces = SplitFaces(num_vertices, faces, edges);
  level.edges = edges.vertices;
  return level;
}

// Each level multiplies the triangles by 4 and adds about 1.5 vertices per triangle.
void RequireIdsFit(const Mesh& coarse, int levels, const std::string& where) {
  Require(levels >= 0, where,
          "the number of subdivision levels must be at least 0, got " + std::to_string(levels));
  double faces = coarse.num_faces();
  for (int l = 0; l < levels; ++l) faces *= 4.0;
  Require(coarse.num_vertices() + 2.0 * faces < std::numeric_limits<int>::max(), where,
          std::to_string(levels) + " subdivision levels would make more vertices than ids allow");
}

void RequireCoarseVertices(const SubdivisionStencil& stencil,
                           const Eigen::Matrix3Xd& coarse_vertices, const std::string& where) {
  Require(coarse_vertices.cols() == stencil.num_coarse_vertices, where,
          "the frame has " + std::to_string(coarse_vertices.cols()) +
              " vertices but the subdivision was built for " +
              std::to_string(stencil.num_coarse_vertices));
}

}  // namespace

int SubdivisionStencil::FineVertexOfCoarse(int coarse_vertex) const {
  Require(coarse_vertex >= 0 && coarse_vertex < num_coarse_vertices, "subdivision",
          "coarse vertex " + std::to_string(coarse_vertex) + " does not exist (the mesh has " +
              std::to_string(num_coarse_vertices) + ")");
  return coarse_vertex;
}

SubdivisionStencil BuildLoopSubdivision(const Mesh& coarse, int levels, const std::string& where) {
  coarse.Validate(where);
  RequireIdsFit(coarse, levels, where);
  SubdivisionStencil stencil;
  stencil.num_coarse_vertices = coarse.num_vertices();
  stencil.levels = levels;
  stencil.matrix.resize(coarse.num_vertices(), coarse.num_vertices());
  stencil.matrix.setIdentity();
  stencil.faces = coarse.faces;
  for (int l = 0; l < levels; ++l) {
    OneLevel level = SubdivideOnce(stencil.num_fine_vertices(), stencil.faces, where);
    if (l == 0) {
      stencil.matrix = std::move(level.matrix);  // Skips the product with the identity.
    } else {
      Eigen::SparseMatrix<double> composed = level.matrix * stencil.matrix;
      stencil.matrix.swap(composed);
    }
    stencil.faces = std::move(level.faces);
    stencil.level_edges.push_back(std::move(level.edges));
  }
  return stencil;
}

Mesh ApplySubdivision(const SubdivisionStencil& stencil, const Eigen::Matrix3Xd& coarse_vertices,
                      const std::string& where) {
  RequireCoarseVertices(stencil, coarse_vertices, where);
  Mesh fine;
  fine.vertices = coarse_vertices * stencil.matrix.transpose();
  fine.faces = stencil.faces;
  return fine;
}

Mesh ApplyLinearSubdivision(const SubdivisionStencil& stencil,
                            const Eigen::Matrix3Xd& coarse_vertices, const std::string& where) {
  RequireCoarseVertices(stencil, coarse_vertices, where);
  Mesh fine;
  fine.vertices.resize(3, stencil.num_fine_vertices());
  fine.vertices.leftCols(coarse_vertices.cols()) = coarse_vertices;
  // Edge points follow their parents in the numbering, so each level reads only what is set.
  Eigen::Index next = coarse_vertices.cols();
  for (const Eigen::Matrix2Xi& edges : stencil.level_edges) {
    for (int e = 0; e < edges.cols(); ++e, ++next) {
      fine.vertices.col(next) =
          0.5 * (fine.vertices.col(edges(0, e)) + fine.vertices.col(edges(1, e)));
    }
  }
  fine.faces = stencil.faces;
  return fine;
}

std::vector<bool> SubdivideVertexMask(const SubdivisionStencil& stencil,
                                      const std::vector<bool>& coarse_mask,
                                      const std::string& where) {
  Require(static_cast<int>(coarse_mask.size()) == stencil.num_coarse_vertices, where,
          "the vertex mask has " + std::to_string(coarse_mask.size()) +
              " entries but the mesh has " + std::to_string(stencil.num_coarse_vertices) +
              " vertices");
  std::vector<bool> mask = coarse_mask;
  for (const Eigen::Matrix2Xi& edges : stencil.level_edges) {
    mask.reserve(mask.size() + edges.cols());
    for (int e = 0; e < edges.cols(); ++e) mask.push_back(mask[edges(0, e)] && mask[edges(1, e)]);
  }
  return mask;
}

}  // namespace finecap
