// Taubin's lambda|mu smoothing along the vertex normals, with cotangent weights.
#include "finecap/geometry/mesh_smoothing.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Geometry>
#include <Eigen/SparseCore>

#include "finecap/geometry/mesh_edges.h"
#include "finecap/util/error.h"

namespace finecap {
namespace {

// Cotangent of the angle at `apex` of the triangle (apex, a, b); 0 for a degenerate triangle,
// whose angles say nothing about the surface.
double CotangentAt(const Eigen::Vector3d& apex, const Eigen::Vector3d& a,
                   const Eigen::Vector3d& b) {
  const Eigen::Vector3d u = a - apex;
  const Eigen::Vector3d v = b - apex;
  const double sine = u.cross(v).norm();
  const double scale = u.squaredNorm() * v.squaredNorm();
  if (!(sine > 1e-12 * std::sqrt(scale))) return 0.0;
  return u.dot(v) / sine;
}

// Per edge, half the sum of the cotangents of the angles opposite it (one per triangle on it),
// clamped at zero: a negative weight (an edge that is not locally Delaunay) would push a vertex
// away from its neighbour.
std::vector<double> CotangentEdgeWeights(const Mesh& mesh, const MeshEdges& edges) {
  std::vector<double> weights(edges.num_edges(), 0.0);
  for (int e = 0; e < edges.num_edges(); ++e) {
    double weight = 0.0;
    for (int k = edges.side_offsets[e]; k < edges.side_offsets[e + 1]; ++k) {
      const int face = SideFace(edges.sides[k]);
      const int corner = SideCorner(edges.sides[k]);
      const int a = mesh.faces(corner, face);
      const int b = mesh.faces((corner + 1) % 3, face);
      const int apex = mesh.faces((corner + 2) % 3, face);
      weight +=
          0.5 * CotangentAt(mesh.vertices.col(apex), mesh.vertices.col(a), mesh.vertices.col(b));
    }
    weights[e] = std::max(weight, 0.0);
  }
  return weights;
}

// The row-normalised weights of the Laplacian: row i holds w_ij / sum_j w_ij over the neighbours
// j of vertex i, so that (vertices * weights^T).col(i) is the weighted mean of i's neighbours. A
// vertex whose cotangent weights sum to zero gets uniform weights.
Eigen::SparseMatrix<double, Eigen::RowMajor> NeighbourWeights(const Mesh& mesh) {
  const MeshEdges edges = BuildMeshEdges(mesh.faces);
  const std::vector<double> edge_weights = CotangentEdgeWeights(mesh, edges);
  const int n = mesh.num_vertices();
  Eigen::VectorXd sums = Eigen::VectorXd::Zero(n);
  Eigen::VectorXd degrees = Eigen::VectorXd::Zero(n);
  for (int e = 0; e < edges.num_edges(); ++e) {
    for (int end = 0; end < 2; ++end) {
      sums(edges.vertices(end, e)) += edge_weights[e];
      degrees(edges.vertices(end, e)) += 1.0;
    }
  }
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(2 * edges.num_edges());
  for (int e = 0; e < edges.num_edges(); ++e) {
    for (int end = 0; end < 2; ++end) {
      const int row = edges.vertices(end, e);
      const double weight = sums(row) > 0.0 ? edge_weights[e] / sums(row) : 1.0 / degrees(row);
      entries.emplace_back(row, edges.vertices(1 - end, e), weight);
    }
  }
  Eigen::SparseMatrix<double, Eigen::RowMajor> weights(n, n);
  weights.setFromTriplets(entries.begin(), entries.end());
  return weights;
}

// Moves every vertex by `factor` times the normal part of its Laplacian. Vertices without
// neighbours have a zero row and a zero normal, and stay.
void NormalLaplacianStep(const Eigen::SparseMatrix<double, Eigen::RowMajor>& weights,
                         const Eigen::VectorXd& has_neighbours, double factor, Mesh* mesh) {
  const Eigen::Matrix3Xd normals = ComputeVertexNormals(*mesh);
  const Eigen::Matrix3Xd laplacian =
      mesh->vertices * weights.transpose() - mesh->vertices * has_neighbours.asDiagonal();
  const Eigen::RowVectorXd along_normal = (laplacian.cwiseProduct(normals)).colwise().sum();
  mesh->vertices += factor * (normals * along_normal.asDiagonal());
}

}  // namespace

const OptionFields<TaubinSmoothingOptions>& TaubinSmoothingOptions::Fields() {
  static const OptionFields<TaubinSmoothingOptions> fields = [] {
    OptionFields<TaubinSmoothingOptions> f;
    f.AddInt("iterations", &TaubinSmoothingOptions::iterations,
             "synth.coarse smoothed: Taubin iterations (lambda and mu step each), the strength of "
             "the smoothing.",
             1, 100000);
    f.AddDouble("lambda", &TaubinSmoothingOptions::lambda, "Taubin's shrinking step factor.", 1e-3,
                1.0);
    f.AddDouble("mu", &TaubinSmoothingOptions::mu,
                "Taubin's inflating step factor (negative, usually slightly larger in magnitude "
                "than lambda; (1 - 2 lambda)(1 - 2 mu) >= -1).",
                -1.0, 0.0);
    return f;
  }();
  return fields;
}

void TaubinSmoothingOptions::Check(const std::string& where) const {
  Fields().CheckValues(*this, where + ".");
  // The fastest wave a mesh carries (Laplacian eigenvalue 2) is scaled by this per iteration;
  // below -1 it would grow from one iteration to the next instead of fading.
  const double fastest = (1.0 - 2.0 * lambda) * (1.0 - 2.0 * mu);
  Require(fastest >= -1.0, where + ".mu",
          "is " + std::to_string(mu) + " with lambda " + std::to_string(lambda) +
              ": together they make the smoothing unstable ((1 - 2 lambda)(1 - 2 mu) = " +
              std::to_string(fastest) + " < -1, the finest detail grows); use a smaller lambda " +
              "or |mu|");
}

Eigen::Matrix3Xd TaubinSmooth(const Mesh& mesh, const TaubinSmoothingOptions& options) {
  options.Check("TaubinSmoothingOptions");
  const Eigen::SparseMatrix<double, Eigen::RowMajor> weights = NeighbourWeights(mesh);
  // 1 for a vertex with neighbours (its row sums to 1), 0 for one in no triangle.
  Eigen::VectorXd has_neighbours = weights * Eigen::VectorXd::Ones(mesh.num_vertices());
  has_neighbours = (has_neighbours.array() > 0.5).cast<double>();
  Mesh smoothed = mesh;
  for (int i = 0; i < options.iterations; ++i) {
    NormalLaplacianStep(weights, has_neighbours, options.lambda, &smoothed);
    NormalLaplacianStep(weights, has_neighbours, options.mu, &smoothed);
  }
  return smoothed.vertices;
}

}  // namespace finecap
