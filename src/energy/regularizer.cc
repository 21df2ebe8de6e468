#include "finecap/energy/regularizer.h"

#include "finecap/model/gaussian_overlap.h"

namespace finecap {

Regularizer::Regularizer(const VertexNeighbourhoods& neighbourhoods,
                         const std::vector<int>& vertex_ids, int rings, double unit_scale)
    : unit_scale_(unit_scale) {
  std::vector<int> surface_of_vertex(neighbourhoods.num_vertices(), -1);
  for (int s = 0; s < static_cast<int>(vertex_ids.size()); ++s) {
    surface_of_vertex[vertex_ids[s]] = s;
  }
  for (int s = 0; s < static_cast<int>(vertex_ids.size()); ++s) {
    const int v = vertex_ids[s];
    for (int e = neighbourhoods.offsets[v]; e < neighbourhoods.offsets[v + 1]; ++e) {
      const int j = surface_of_vertex[neighbourhoods.neighbours[e]];
      // Each pair of two surface Gaussians once (from its lower index); a fixed neighbour once.
      if (j >= 0 && j < s) continue;
      const double weight = Wendland(neighbourhoods.edge_distances[e], rings);
      if (weight > 0.0) pairs_.push_back({s, j, weight});
    }
  }
}

double Regularizer::Evaluate(const Eigen::VectorXd& k, Eigen::VectorXd* gradient) const {
  if (gradient != nullptr) *gradient = Eigen::VectorXd::Zero(k.size());
  const double u2 = unit_scale_ * unit_scale_;
  double energy = 0.0;
  for (const Pair& pair : pairs_) {
    const double difference = k[pair.a] - (pair.b >= 0 ? k[pair.b] : 0.0);
    energy += 2.0 * pair.weight * u2 * difference * difference;
    if (gradient == nullptr) continue;
    const double derivative = 4.0 * pair.weight * u2 * difference;
    (*gradient)[pair.a] += derivative;
    if (pair.b >= 0) (*gradient)[pair.b] -= derivative;
  }
  return energy;
}

void Regularizer::AverageOverNeighbours(int rounds, Eigen::MatrixXd* values) const {
  if (rounds <= 0) return;
  // Each Gaussian's values as one column, contiguous: the pairs visit the Gaussians in mesh
  // order, and a row of the column-major `values` spans a cache line per column (the sweep's 33
  // samples). The sums are the same, in the same order.
  Eigen::MatrixXd columns = values->transpose();
  Eigen::VectorXd count = Eigen::VectorXd::Ones(columns.cols());
  for (const Pair& pair : pairs_) {
    if (pair.b < 0) continue;
    count[pair.a] += 1.0;
    count[pair.b] += 1.0;
  }
  for (int round = 0; round < rounds; ++round) {
    Eigen::MatrixXd sum = columns;
    for (const Pair& pair : pairs_) {
      if (pair.b < 0) continue;
      sum.col(pair.a) += columns.col(pair.b);
      sum.col(pair.b) += columns.col(pair.a);
    }
    columns = sum.array().rowwise() / count.transpose().array();
  }
  *values = columns.transpose();
}

}  // namespace finecap
