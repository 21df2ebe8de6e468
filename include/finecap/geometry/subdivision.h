// Subdivision as a fixed linear map. Because the rules of both schemes here depend on the
// connectivity only, the subdivision of a sequence that shares one topology is a single sparse
// matrix S (fine vertices x coarse vertices): every frame's fine vertices are coarse.vertices *
// S^T, and every subdivided frame shares the fine faces, i.e. one topology again.
//
// Two schemes split every triangle in four the same way and differ in where the points go:
//
// Loop (Loop 1987, with the usual crease rules on the boundary of an open mesh) approximates: it
// moves every input vertex towards a smoother limit surface.
//  * interior vertex of valence n: (1 - n * beta) * v + beta * (sum of its n neighbours), with
//    Loop's original beta(n) = (5/8 - (3/8 + 1/4 * cos(2 * pi / n))^2) / n (1/16 when n = 6, so a
//    regular vertex keeps 5/8 of itself and takes 1/16 of each neighbour);
//  * boundary vertex (on exactly two boundary edges): 3/4 * v + 1/8 * each boundary neighbour, so
//    an open boundary (a skirt's hem) is subdivided as a cubic B-spline curve of its own;
//  * interior edge (a, b) with opposite vertices c, d: 3/8 * (a + b) + 1/8 * (c + d);
//  * boundary edge (a, b): 1/2 * (a + b);
//  * a vertex on more than two boundary edges (where two sheets touch at a point) and a vertex in
//    no triangle keep their position.
// Corners are not tagged: a boundary vertex where the boundary turns sharply is smoothed like any
// other and rounds the corner (a closed hem, like a skirt's, has none).
//
// Modified butterfly (Zorin, Schroeder and Sweldens 1996) interpolates: every input vertex stays
// exactly where it is (its row of S is the identity's) and only the edge points are placed.
//  * interior edge (a, b) whose ends each have valence 6 or lie on the boundary: the 8-point
//    butterfly 1/2 * (a + b) + 1/8 * (c + d) - 1/16 * (the four wing vertices), c and d opposite
//    the edge and each wing vertex across one of the other sides of the edge's two triangles. A
//    wing missing because that side is on the boundary is completed by reflection, x + y - z for
//    the side (x, y) and its opposite corner z (exactly where a regular mesh would have it), so
//    the stencil still reproduces planes;
//  * interior edge from an interior vertex v of valence K != 6 (its neighbours p_0 .. p_{K-1} in
//    order around it, p_0 the edge's other end): 3/4 * v + sum_j s_j * p_j with Zorin's weights
//    s_j = (1/4 + cos(2 pi j / K) + 1/2 * cos(4 pi j / K)) / K for K >= 5, (5/12, -1/12, -1/12)
//    for K = 3 and (3/8, 0, -1/8, 0) for K = 4; when both ends are such vertices, the mean of the
//    two stencils;
//  * boundary edge (a, b): the 4-point curve rule 9/16 * (a + b) - 1/16 * (a' + b'), a' and b' the
//    next vertices along the boundary beyond a and b, so an open boundary is subdivided as an
//    interpolating curve of its own; where a or b is on more than two boundary edges, 1/2 * (a +
//    b).
// An interior vertex whose triangles do not close one fan around it (two fans touching at a point)
// has no order of its neighbours and takes the 8-point butterfly, as a boundary vertex does.
//
// Every row of S sums to 1 in both schemes, so the map is affine-invariant: planes stay planar.
//
// Vertex numbering, an invariant other code relies on: the first num_coarse_vertices fine
// vertices are the coarse vertices, in order; then come the edge points of each level in the edge
// order of MeshEdges (edges sorted by their vertex pair). Each coarse triangle (a, b, c) becomes
// four fine triangles with its orientation: (a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca).
#ifndef FINECAP_GEOMETRY_SUBDIVISION_H_
#define FINECAP_GEOMETRY_SUBDIVISION_H_

#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include "finecap/geometry/mesh.h"
#include "finecap/util/enum_names.h"

namespace finecap {

// The subdivision rules (see above): kLoop approximates, kButterfly (modified butterfly)
// interpolates the coarse vertices on a smooth surface, kLinear keeps the coarse surface itself
// (every vertex stays, every edge point at its edge's midpoint).
enum class SubdivisionScheme { kLoop, kButterfly, kLinear };
// loop, butterfly, linear.
const std::vector<EnumName<SubdivisionScheme>>& EnumNames(SubdivisionScheme);

struct SubdivisionStencil {
  // S: num_fine_vertices x num_coarse_vertices; row i holds the weights of fine vertex i. For
  // several levels it is the product S_levels * ... * S_1.
  Eigen::SparseMatrix<double> matrix;
  Eigen::Matrix3Xi faces;  // Fine triangles, oriented as their coarse triangles.
  int num_coarse_vertices = 0;
  int levels = 0;
  // level_edges[l](:, e) are the two parents of the edge point num_vertices_before(l) + e, as
  // vertex ids of level l's input mesh (level 0 is the coarse mesh).
  std::vector<Eigen::Matrix2Xi> level_edges;

  int num_fine_vertices() const { return static_cast<int>(matrix.rows()); }
  // The fine vertex that sits where coarse vertex `coarse_vertex` does: the same id, by the
  // numbering invariant above. Throws Error when the id is out of range.
  int FineVertexOfCoarse(int coarse_vertex) const;
};

// Builds S and the fine faces for `levels` rounds of subdivision by `scheme` (0 gives the identity
// and the coarse faces). Uses the connectivity of `coarse` only. Throws Error(where, ...) when the
// mesh fails Mesh::Validate, when levels is negative or would overflow the vertex ids, or, but
// for kLinear, when an edge is in three or more triangles (non-manifold: Loop's and the
// butterfly's rules are not defined there; a midpoint is).
SubdivisionStencil BuildSubdivision(SubdivisionScheme scheme, const Mesh& coarse, int levels,
                                    const std::string& where = "mesh");

// BuildSubdivision with kLoop, kButterfly and kLinear. The linear scheme's fine mesh is the coarse
// surface itself, its faces split into four at each level: the input as given, sampled at the
// fine vertices, and the points a similarity samples the surface at
// (ConsensusOptions::sample_spacing).
SubdivisionStencil BuildLoopSubdivision(const Mesh& coarse, int levels,
                                        const std::string& where = "mesh");
SubdivisionStencil BuildButterflySubdivision(const Mesh& coarse, int levels,
                                             const std::string& where = "mesh");
SubdivisionStencil BuildLinearSubdivision(const Mesh& coarse, int levels,
                                          const std::string& where = "mesh");

// The fine mesh of one frame: vertices coarse_vertices * S^T, faces the stencil's. Throws
// Error(where, ...) when coarse_vertices has not num_coarse_vertices columns; `where` names the
// frame's file.
Mesh ApplySubdivision(const SubdivisionStencil& stencil, const Eigen::Matrix3Xd& coarse_vertices,
                      const std::string& where = "subdivision");

// The coarse surface as given, sampled at the fine vertices of `stencil`: every edge point at
// the midpoint of its two parents, level by level (midpoint subdivision, with the stencil's
// numbering and faces). Every fine vertex is then the linear interpolation of the corners of its
// coarse triangle, and the fine mesh is the coarse one face for face, where Loop's rules would
// smooth it. What measures a coarse mesh as its user gave it against a finer truth. Throws
// Error(where, ...) as ApplySubdivision does.
Mesh ApplyLinearSubdivision(const SubdivisionStencil& stencil,
                            const Eigen::Matrix3Xd& coarse_vertices,
                            const std::string& where = "subdivision");

// Carries a per-vertex mask (e.g. the vertices to refine) to the fine mesh: a coarse vertex keeps
// its flag and an edge point is in the mask exactly when both of its parents are, level by level.
// Throws Error(where, ...) when the mask has not num_coarse_vertices entries; `where` names the
// mask's file.
std::vector<bool> SubdivideVertexMask(const SubdivisionStencil& stencil,
                                      const std::vector<bool>& coarse_mask,
                                      const std::string& where = "subdivision");

}  // namespace finecap

#endif  // FINECAP_GEOMETRY_SUBDIVISION_H_
