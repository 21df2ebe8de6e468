#include "finecap/geometry/subdivision.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

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

void RequireManifoldEdges(SubdivisionScheme scheme, const MeshEdges& edges,
                          const std::string& where) {
  for (int e = 0; e < edges.num_edges(); ++e) {
    if (edges.NumSides(e) <= 2) continue;
    throw Error(where, "edge (" + std::to_string(edges.vertices(0, e)) + ", " +
                           std::to_string(edges.vertices(1, e)) + ") is shared by " +
                           std::to_string(edges.NumSides(e)) +
                           " triangles (a non-manifold edge): " + EnumToString(scheme) +
                           " subdivision needs every edge in at most two");
  }
}

// How many edges each vertex is on, all of them and those on the boundary.
struct Valences {
  std::vector<int> all;
  std::vector<int> boundary;
};

Valences CountValences(int num_vertices, const MeshEdges& edges) {
  Valences valences{std::vector<int>(num_vertices, 0), std::vector<int>(num_vertices, 0)};
  for (int e = 0; e < edges.num_edges(); ++e) {
    for (int end = 0; end < 2; ++end) {
      ++valences.all[edges.vertices(end, e)];
      if (edges.IsBoundary(e)) ++valences.boundary[edges.vertices(end, e)];
    }
  }
  return valences;
}

// How each vertex is smoothed: the weight on itself and the weight on each neighbour it takes
// (interior vertices take all neighbours, boundary vertices their two boundary neighbours only).
struct VertexRule {
  double self = 1.0;
  double interior_neighbour = 0.0;
  double boundary_neighbour = 0.0;
};

std::vector<VertexRule> VertexRules(int num_vertices, const MeshEdges& edges) {
  const Valences valences = CountValences(num_vertices, edges);
  std::vector<VertexRule> rules(num_vertices);
  for (int v = 0; v < num_vertices; ++v) {
    const int valence = valences.all[v];
    if (valence > 0 && valences.boundary[v] == 0) {
      const double beta = LoopBeta(valence);
      rules[v] = {1.0 - valence * beta, beta, 0.0};
    } else if (valences.boundary[v] == 2) {
      rules[v] = {0.75, 0.0, 0.125};
    }  // Otherwise isolated or where sheets touch: the default keeps the vertex in place.
  }
  return rules;
}

void AddLoopVertexPoints(const MeshEdges& edges, const std::vector<VertexRule>& rules,
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

// The corner of a triangle opposite its side `side`.
int OppositeCorner(const Eigen::Matrix3Xi& faces, int side) {
  return faces((SideCorner(side) + 2) % 3, SideFace(side));
}

void AddLoopEdgePoints(int num_vertices, const Eigen::Matrix3Xi& faces, const MeshEdges& edges,
                       Triplets* triplets) {
  for (int e = 0; e < edges.num_edges(); ++e) {
    const int row = num_vertices + e;
    const bool boundary = edges.IsBoundary(e);
    const double end_weight = boundary ? 0.5 : 3.0 / 8.0;
    triplets->emplace_back(row, edges.vertices(0, e), end_weight);
    triplets->emplace_back(row, edges.vertices(1, e), end_weight);
    if (boundary) continue;
    for (int k = edges.side_offsets[e]; k < edges.side_offsets[e + 1]; ++k) {
      triplets->emplace_back(row, OppositeCorner(faces, edges.sides[k]), 1.0 / 8.0);
    }
  }
}

void AddLoopPoints(int num_vertices, const Eigen::Matrix3Xi& faces, const MeshEdges& edges,
                   Triplets* triplets) {
  AddLoopVertexPoints(edges, VertexRules(num_vertices, edges), triplets);
  AddLoopEdgePoints(num_vertices, faces, edges, triplets);
}

// Zorin's weights s_0 .. s_{K-1} of the neighbours of an interior vertex of valence K != 6, in
// order around it from the edge's other end; the vertex itself takes 3/4.
std::vector<double> ZorinWeights(int valence) {
  if (valence == 3) return {5.0 / 12.0, -1.0 / 12.0, -1.0 / 12.0};
  if (valence == 4) return {3.0 / 8.0, 0.0, -1.0 / 8.0, 0.0};
  std::vector<double> weights(valence);
  for (int j = 0; j < valence; ++j) {
    const double angle = 2.0 * M_PI * j / valence;
    weights[j] = (0.25 + std::cos(angle) + 0.5 * std::cos(2.0 * angle)) / valence;
  }
  return weights;
}

// The neighbours of every interior vertex in order around it (either way round: Zorin's weights
// are symmetric), found by walking the fan of its triangles. Empty for a vertex on the boundary,
// in no triangle, or whose triangles make more than one fan.
std::vector<std::vector<int>> OrderedRings(int num_vertices, const Eigen::Matrix3Xi& faces,
                                           const Valences& valences) {
  // links[v]: for each triangle at v, its side opposite v, as the pair of the other two corners.
  std::vector<std::vector<std::pair<int, int>>> links(num_vertices);
  for (int f = 0; f < faces.cols(); ++f) {
    for (int corner = 0; corner < 3; ++corner) {
      links[faces(corner, f)].emplace_back(faces((corner + 1) % 3, f), faces((corner + 2) % 3, f));
    }
  }
  std::vector<std::vector<int>> rings(num_vertices);
  for (int v = 0; v < num_vertices; ++v) {
    std::vector<std::pair<int, int>>& link = links[v];
    if (valences.boundary[v] != 0 || link.empty()) continue;
    // Interior and manifold: each neighbour is on exactly two link sides, so the walk closes.
    std::vector<int> ring = {link.front().first};
    int current = link.front().second;
    link.erase(link.begin());
    while (current != ring.front()) {
      ring.push_back(current);
      const auto next = std::find_if(link.begin(), link.end(), [current](const auto& side) {
        return side.first == current || side.second == current;
      });
      if (next == link.end()) break;
      const int following = next->first == current ? next->second : next->first;
      link.erase(next);
      current = following;
    }
    if (current == ring.front() && link.empty() &&
        static_cast<int>(ring.size()) == valences.all[v]) {
      rings[v] = std::move(ring);
    }
  }
  return rings;
}

// The two neighbours of each vertex along the boundary, or -1 for a vertex that is not on exactly
// two boundary edges.
std::vector<std::array<int, 2>> BoundaryNeighbours(int num_vertices, const MeshEdges& edges,
                                                   const Valences& valences) {
  std::vector<std::array<int, 2>> neighbours(num_vertices, {-1, -1});
  for (int e = 0; e < edges.num_edges(); ++e) {
    if (!edges.IsBoundary(e)) continue;
    for (int end = 0; end < 2; ++end) {
      const int v = edges.vertices(end, e);
      if (valences.boundary[v] != 2) continue;
      neighbours[v][neighbours[v][0] < 0 ? 0 : 1] = edges.vertices(1 - end, e);
    }
  }
  return neighbours;
}

// Builds the rows of the butterfly's edge points of one level.
class ButterflyEdgePoints {
 public:
  ButterflyEdgePoints(int num_vertices, const Eigen::Matrix3Xi& faces, const MeshEdges& edges)
      : num_vertices_(num_vertices),
        faces_(faces),
        edges_(edges),
        valences_(CountValences(num_vertices, edges)),
        rings_(OrderedRings(num_vertices, faces, valences_)),
        boundary_neighbours_(BoundaryNeighbours(num_vertices, edges, valences_)) {}

  void Add(Triplets* triplets) const {
    for (int e = 0; e < edges_.num_edges(); ++e) {
      const int row = num_vertices_ + e;
      const int a = edges_.vertices(0, e), b = edges_.vertices(1, e);
      if (edges_.IsBoundary(e)) {
        AddFourPoint(row, a, b, triplets);
      } else if (!IsExtraordinary(a) && !IsExtraordinary(b)) {
        AddEightPoint(row, e, triplets);
      } else {
        const double share = IsExtraordinary(a) && IsExtraordinary(b) ? 0.5 : 1.0;
        if (IsExtraordinary(a)) AddExtraordinary(row, a, b, share, triplets);
        if (IsExtraordinary(b)) AddExtraordinary(row, b, a, share, triplets);
      }
    }
  }

 private:
  // An interior vertex of valence other than 6 with one fan of triangles around it.
  bool IsExtraordinary(int v) const { return !rings_[v].empty() && rings_[v].size() != 6; }

  void AddFourPoint(int row, int a, int b, Triplets* triplets) const {
    const int before_a = OtherBoundaryNeighbour(a, b);
    const int after_b = OtherBoundaryNeighbour(b, a);
    if (before_a < 0 || after_b < 0) {
      triplets->emplace_back(row, a, 0.5);
      triplets->emplace_back(row, b, 0.5);
      return;
    }
    triplets->emplace_back(row, a, 9.0 / 16.0);
    triplets->emplace_back(row, b, 9.0 / 16.0);
    triplets->emplace_back(row, before_a, -1.0 / 16.0);
    triplets->emplace_back(row, after_b, -1.0 / 16.0);
  }

  // The neighbour of v along the boundary other than `neighbour`, or -1 if v has none.
  int OtherBoundaryNeighbour(int v, int neighbour) const {
    const std::array<int, 2>& both = boundary_neighbours_[v];
    if (both[0] < 0 || both[1] < 0) return -1;
    return both[0] == neighbour ? both[1] : both[0];
  }

  void AddEightPoint(int row, int e, Triplets* triplets) const {
    triplets->emplace_back(row, edges_.vertices(0, e), 0.5);
    triplets->emplace_back(row, edges_.vertices(1, e), 0.5);
    for (int k = edges_.side_offsets[e]; k < edges_.side_offsets[e + 1]; ++k) {
      const int side = edges_.sides[k];
      const int face = SideFace(side), corner = SideCorner(side);
      triplets->emplace_back(row, OppositeCorner(faces_, side), 1.0 / 8.0);
      AddWing(row, 3 * face + (corner + 1) % 3, triplets);
      AddWing(row, 3 * face + (corner + 2) % 3, triplets);
    }
  }

  // -1/16 of the vertex across triangle side `side`, or of its reflection when the side is on
  // the boundary.
  void AddWing(int row, int side, Triplets* triplets) const {
    const int e = edges_.face_edges(SideCorner(side), SideFace(side));
    for (int k = edges_.side_offsets[e]; k < edges_.side_offsets[e + 1]; ++k) {
      if (edges_.sides[k] == side) continue;
      triplets->emplace_back(row, OppositeCorner(faces_, edges_.sides[k]), -1.0 / 16.0);
      return;
    }
    // The reflection x + y - z of the opposite corner z through the side (x, y).
    triplets->emplace_back(row, edges_.vertices(0, e), -1.0 / 16.0);
    triplets->emplace_back(row, edges_.vertices(1, e), -1.0 / 16.0);
    triplets->emplace_back(row, OppositeCorner(faces_, side), 1.0 / 16.0);
  }

  // `share` of Zorin's stencil of the extraordinary vertex v for its edge to `other`.
  void AddExtraordinary(int row, int v, int other, double share, Triplets* triplets) const {
    const std::vector<int>& ring = rings_[v];
    const int valence = static_cast<int>(ring.size());
    const int first = static_cast<int>(std::find(ring.begin(), ring.end(), other) - ring.begin());
    const std::vector<double> weights = ZorinWeights(valence);
    triplets->emplace_back(row, v, share * 0.75);
    for (int j = 0; j < valence; ++j) {
      if (weights[j] != 0.0)
        triplets->emplace_back(row, ring[(first + j) % valence], share * weights[j]);
    }
  }

  const int num_vertices_;
  const Eigen::Matrix3Xi& faces_;
  const MeshEdges& edges_;
  const Valences valences_;
  const std::vector<std::vector<int>> rings_;
  const std::vector<std::array<int, 2>> boundary_neighbours_;
};

void AddButterflyPoints(int num_vertices, const Eigen::Matrix3Xi& faces, const MeshEdges& edges,
                        Triplets* triplets) {
  for (int v = 0; v < num_vertices; ++v) triplets->emplace_back(v, v, 1.0);
  ButterflyEdgePoints(num_vertices, faces, edges).Add(triplets);
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

// The linear scheme's edge points: the midpoints of their edges.
void AddMidpoints(int num_vertices, const MeshEdges& edges, Triplets* triplets) {
  for (int e = 0; e < edges.num_edges(); ++e) {
    triplets->emplace_back(num_vertices + e, edges.vertices(0, e), 0.5);
    triplets->emplace_back(num_vertices + e, edges.vertices(1, e), 0.5);
  }
}

OneLevel SubdivideOnce(SubdivisionScheme scheme, int num_vertices, const Eigen::Matrix3Xi& faces,
                       const std::string& where) {
  const MeshEdges edges = BuildMeshEdges(faces);
  // Midpoints are defined on any edge; the smooth schemes' rules need at most two sides.
  if (scheme != SubdivisionScheme::kLinear) RequireManifoldEdges(scheme, edges, where);
  Triplets triplets;
  if (scheme == SubdivisionScheme::kButterfly) {
    triplets.reserve(num_vertices + 10 * static_cast<size_t>(edges.num_edges()));
    AddButterflyPoints(num_vertices, faces, edges, &triplets);
  } else if (scheme == SubdivisionScheme::kLinear) {
    triplets.reserve(num_vertices + 2 * static_cast<size_t>(edges.num_edges()));
    for (int v = 0; v < num_vertices; ++v) triplets.emplace_back(v, v, 1.0);
    AddMidpoints(num_vertices, edges, &triplets);
  } else {
    triplets.reserve(7 * static_cast<size_t>(num_vertices) + 4 * edges.num_edges());
    AddLoopPoints(num_vertices, faces, edges, &triplets);
  }
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

const std::vector<EnumName<SubdivisionScheme>>& EnumNames(SubdivisionScheme) {
  static const std::vector<EnumName<SubdivisionScheme>> names = {
      {SubdivisionScheme::kLoop, "loop"},
      {SubdivisionScheme::kButterfly, "butterfly"},
      {SubdivisionScheme::kLinear, "linear"}};
  return names;
}

SubdivisionStencil BuildSubdivision(SubdivisionScheme scheme, const Mesh& coarse, int levels,
                                    const std::string& where) {
  Require(IsKnownEnum(scheme), where,
          "unknown subdivision scheme " + std::to_string(static_cast<int>(scheme)));
  coarse.Validate(where);
  RequireIdsFit(coarse, levels, where);
  SubdivisionStencil stencil;
  stencil.num_coarse_vertices = coarse.num_vertices();
  stencil.levels = levels;
  stencil.matrix.resize(coarse.num_vertices(), coarse.num_vertices());
  stencil.matrix.setIdentity();
  stencil.faces = coarse.faces;
  for (int l = 0; l < levels; ++l) {
    OneLevel level = SubdivideOnce(scheme, stencil.num_fine_vertices(), stencil.faces, where);
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

SubdivisionStencil BuildLoopSubdivision(const Mesh& coarse, int levels, const std::string& where) {
  return BuildSubdivision(SubdivisionScheme::kLoop, coarse, levels, where);
}

SubdivisionStencil BuildButterflySubdivision(const Mesh& coarse, int levels,
                                             const std::string& where) {
  return BuildSubdivision(SubdivisionScheme::kButterfly, coarse, levels, where);
}

SubdivisionStencil BuildLinearSubdivision(const Mesh& coarse, int levels,
                                          const std::string& where) {
  return BuildSubdivision(SubdivisionScheme::kLinear, coarse, levels, where);
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
