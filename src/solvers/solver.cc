#include "finecap/solvers/solver.h"

#include <cmath>
#include <vector>

#include "finecap/util/error.h"
#include "solvers/solvers_internal.h"

namespace finecap {

double LeastSquaresCost(FrameEnergy* energy, const Eigen::VectorXd& k) {
  std::vector<double> block_costs;
  energy->similarity().BlockCosts(k, &block_costs);
  double sum_of_squares = 0.0;
  for (double cost : block_costs) sum_of_squares += cost;
  // The regulariser's residuals are 2 sqrt(w T) u (k_a - k_b): their half sum of squares is
  // w_reg * E_reg; the prior's, sqrt(p_s) k_s, give E_prior.
  const Eigen::VectorXd& prior = energy->prior_curvature();
  return 0.5 * sum_of_squares +
         energy->options().w_reg * energy->regularizer().Evaluate(k, nullptr) +
         0.5 * k.dot(prior.cwiseProduct(k));
}

void EvaluateEnergyAndCost(FrameEnergy* energy, const Eigen::VectorXd& k, double* energy_value,
                           double* cost) {
  *cost = LeastSquaresCost(energy, k);
  *energy_value = energy->similarity().IsLeastSquares() ? -*cost : energy->Evaluate(k, nullptr);
}

SolverSummary Solve(FrameEnergy* energy, const SolverOptions& options, Eigen::VectorXd* k) {
  options.Check();
  Require(k->size() == energy->num_parameters(), "solver", "k has the wrong size");
  const double k_max = energy->options().k_max;
  *k = k->cwiseMax(-k_max).cwiseMin(k_max);
  SolverSummary summary;
  summary.solver = EnumToString(options.type);
  if (options.type == SolverType::kCeres && energy->similarity().IsLeastSquares() &&
      k->size() > 0) {
    // Ceres' own start and final costs are the least-squares cost, and so give E.
    const Eigen::VectorXd start = *k;
    summary.ls_cost_start = summary.ls_cost_end = std::nan("");
    internal::SolveWithCeres(energy, options, k, &summary);
    if (std::isnan(summary.ls_cost_start)) {
      summary.ls_cost_start = LeastSquaresCost(energy, start);
      summary.ls_cost_end = LeastSquaresCost(energy, *k);
    }
    summary.energy_start = -summary.ls_cost_start;
    summary.energy_end = -summary.ls_cost_end;
    return summary;
  }
  EvaluateEnergyAndCost(energy, *k, &summary.energy_start, &summary.ls_cost_start);
  if (options.type == SolverType::kCeres) {
    internal::SolveWithCeres(energy, options, k, &summary);
  } else if (options.type == SolverType::kGradientAscent) {
    internal::SolveWithGradientAscent(*energy, options, k, &summary);
  } else {
    internal::SolveWithLbfgs(*energy, options, k, &summary);
  }
  EvaluateEnergyAndCost(energy, *k, &summary.energy_end, &summary.ls_cost_end);
  return summary;
}

}  // namespace finecap
