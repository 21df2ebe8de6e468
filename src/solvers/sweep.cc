#include "finecap/solvers/sweep.h"

#include <vector>

#include "finecap/util/error.h"

namespace finecap {

namespace {

// costs(s, j): the data cost of Gaussian s at displacement j, summed over the data terms that
// offer sweep costs (SweepCosts).
Eigen::MatrixXd CostsPerGaussian(FrameEnergy* energy, const Eigen::VectorXd& displacements) {
  const int n = energy->num_parameters();
  Eigen::MatrixXd costs = Eigen::MatrixXd::Zero(n, displacements.size());
  Eigen::MatrixXd block_costs;
  for (int t = 0; t < energy->num_data_terms(); ++t) {
    DataTerm& term = energy->data_term(t);
    SweepCosts* sweep = term.sweep_costs();
    if (sweep == nullptr) continue;
    sweep->UniformBlockCosts(n, displacements, &block_costs);
    const auto& blocks = term.residual_blocks();
    // Blocks may share a Gaussian (the paper's similarity): summed in one thread.
    for (int j = 0; j < displacements.size(); ++j) {
      for (int b = 0; b < static_cast<int>(blocks.size()); ++b) {
        for (int s : blocks[b].parameters)
          costs(s, j) += block_costs(b, j) / blocks[b].parameters.size();
      }
    }
  }
  return costs;
}

}  // namespace

Eigen::VectorXd SweepInitialization(FrameEnergy* energy, const SweepOptions& options) {
  options.Check();
  const int n = energy->num_parameters();
  if (options.samples == 0) return Eigen::VectorXd::Zero(n);
  const double k_max = energy->layout().bound;
  const Eigen::VectorXd displacements = Eigen::VectorXd::LinSpaced(options.samples, -k_max, k_max);
  Eigen::MatrixXd costs = CostsPerGaussian(energy, displacements);
  energy->regularizer().AverageOverNeighbours(options.smoothing_rounds, &costs);
  const double step = displacements[1] - displacements[0];
  Eigen::VectorXd k(n);
  for (int s = 0; s < n; ++s) {
    int best = 0;
    // A Gaussian whose curve is flat (no block reaches it, nor its neighbours' costs) has no
    // best displacement: it stays where the coarse mesh puts it rather than at -k_max.
    if (costs.row(s).minCoeff(&best) == costs.row(s).maxCoeff()) {
      k[s] = 0.0;
      continue;
    }
    k[s] = displacements[best];
    // Sub-sample position: the vertex of the parabola through the best sample and its neighbours.
    if (best > 0 && best + 1 < displacements.size()) {
      const double c0 = costs(s, best - 1), c1 = costs(s, best), c2 = costs(s, best + 1);
      const double curvature = c0 - 2.0 * c1 + c2;
      if (curvature > 0.0) k[s] += 0.5 * step * (c0 - c2) / curvature;
    }
  }
  return k;
}

}  // namespace finecap
