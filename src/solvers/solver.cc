#include "finecap/solver.h"

#include "finecap/error.h"
#include "solvers/solvers_internal.h"

namespace finecap {

void SolverOptions::Check() const {
  Require(type == "ceres" || type == "gradient_ascent" || type == "lbfgs", "solver.type",
          "'" + type + "' is not one of: ceres, gradient_ascent, lbfgs");
  Require(max_iterations >= 0, "solver.max_iterations", "must be non-negative");
  Require(function_tolerance >= 0.0, "solver.function_tolerance", "must be non-negative");
  Require(num_threads >= 0, "solver.num_threads", "must be non-negative");
  Require(trust_region == "levenberg_marquardt" || trust_region == "dogleg", "solver.trust_region",
          "'" + trust_region + "' is not one of: levenberg_marquardt, dogleg");
  Require(linear_solver == "sparse_normal_cholesky" || linear_solver == "cgnr" ||
              linear_solver == "dense_qr",
          "solver.linear_solver",
          "'" + linear_solver + "' is not one of: sparse_normal_cholesky, cgnr, dense_qr");
  Require(initial_step > 0.0, "solver.initial_step", "must be positive");
  Require(step_growth >= 1.0, "solver.step_growth", "must be at least 1");
  Require(step_shrink > 0.0 && step_shrink < 1.0, "solver.step_shrink", "must lie in (0, 1)");
  Require(max_step > 0.0, "solver.max_step", "must be positive");
}

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
  summary.solver = options.type;
  summary.ls_cost_start = LeastSquaresCost(energy, *k);
  summary.energy_start = energy->Evaluate(*k, nullptr);
  if (options.type == "ceres") {
    internal::SolveWithCeres(energy, options, k, &summary);
  } else if (options.type == "gradient_ascent") {
    internal::SolveWithGradientAscent(*energy, options, k, &summary);
  } else {
    internal::SolveWithLbfgs(*energy, options, k, &summary);
  }
  summary.energy_end = energy->Evaluate(*k, nullptr);
  summary.ls_cost_end = LeastSquaresCost(energy, *k);
  return summary;
}

}  // namespace finecap
