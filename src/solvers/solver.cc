#include "finecap/solver.h"

#include "finecap/util/error.h"
#include "solvers/solvers_internal.h"

namespace finecap {

double LeastSquaresCost(FrameEnergy* energy, const Eigen::VectorXd& k) {
  SimilarityTerm& similarity = energy->similarity();
  similarity.PrepareResiduals(k, false);
  double sum_of_squares = 0.0;
  std::vector<double> residuals;
  const auto& blocks = similarity.residual_blocks();
  for (int b = 0; b < static_cast<int>(blocks.size()); ++b) {
    residuals.resize(blocks[b].num_residuals);
    similarity.BlockResiduals(b, residuals.data(), nullptr);
    for (double r : residuals) sum_of_squares += r * r;
  }
  // The regulariser's residuals are 2 sqrt(w T) u (k_a - k_b): their half sum of squares is
  // w_reg * E_reg; the prior's, sqrt(p_s) k_s, give E_prior.
  const Eigen::VectorXd& prior = energy->prior_curvature();
  return 0.5 * sum_of_squares +
         energy->options().w_reg * energy->regularizer().Evaluate(k, nullptr) +
         0.5 * k.dot(prior.cwiseProduct(k));
}

SolverSummary Solve(FrameEnergy* energy, const SolverOptions& options, Eigen::VectorXd* k) {
  options.Check();
  Require(k->size() == energy->num_parameters(), "solver", "k has the wrong size");
  const double k_max = energy->options().k_max;
  *k = k->cwiseMax(-k_max).cwiseMin(k_max);
  SolverSummary summary;
  summary.solver = EnumToString(options.type);
  summary.ls_cost_start = LeastSquaresCost(energy, *k);
  summary.energy_start = energy->Evaluate(*k, nullptr);
  if (options.type == SolverType::kCeres) {
    internal::SolveWithCeres(energy, options, k, &summary);
  } else if (options.type == SolverType::kGradientAscent) {
    internal::SolveWithGradientAscent(*energy, options, k, &summary);
  } else {
    internal::SolveWithLbfgs(*energy, options, k, &summary);
  }
  summary.energy_end = energy->Evaluate(*k, nullptr);
  summary.ls_cost_end = LeastSquaresCost(energy, *k);
  return summary;
}

}  // namespace finecap
