#include "finecap/solvers/solver.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <thread>
#include <vector>

#include "finecap/util/error.h"
#include "solvers/solvers_internal.h"

namespace finecap {

double LeastSquaresCost(FrameEnergy* energy, const Eigen::VectorXd& k) {
  std::vector<double> block_costs;
  double sum_of_squares = 0.0;
  for (int t = 0; t < energy->num_data_terms(); ++t) {
    energy->data_term(t).BlockCosts(k, &block_costs);
    for (double cost : block_costs) sum_of_squares += cost;
  }
  // The differences' residuals root (k_a - k_b) and the pulls', sqrt(p_s) (k_s - t_s): their
  // half sums of squares are the parts of E_quad.
  return 0.5 * sum_of_squares + energy->DifferenceEnergy(k, nullptr) + energy->PullEnergy(k);
}

void EvaluateEnergyAndCost(FrameEnergy* energy, const Eigen::VectorXd& k, double* energy_value,
                           double* cost) {
  *cost = LeastSquaresCost(energy, k);
  *energy_value = energy->IsLeastSquares() ? -*cost : energy->Evaluate(k, nullptr);
}

void SolverSummary::AddWork(const SolverSummary& more) {
  iterations += more.iterations;
  evaluations += more.evaluations;
  seconds += more.seconds;
  seconds_evaluation += more.seconds_evaluation;
  seconds_linear_solver += more.seconds_linear_solver;
  seconds_similarity += more.seconds_similarity;
}

int SolverOptions::Threads() const {
  if (num_threads > 0) return num_threads;
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

SolverSummary Solve(FrameEnergy* energy, const SolverOptions& options, Eigen::VectorXd* k) {
  return FrameSolver(energy, options).Solve(k);
}

SolverWorkspace::SolverWorkspace() = default;
SolverWorkspace::~SolverWorkspace() = default;

FrameSolver::FrameSolver(FrameEnergy* energy, const SolverOptions& options,
                         SolverWorkspace* workspace)
    : energy_(energy),
      options_(options),
      workspace_(workspace != nullptr ? workspace : &own_workspace_) {
  options_.Check();
}

FrameSolver::~FrameSolver() = default;

void FrameSolver::SolveWithCeres(Eigen::VectorXd* k, SolverSummary* summary) {
  const internal::Stopwatch clock;
  const bool secant = options_.curvature == CurvatureModel::kSecant;
  std::unique_ptr<internal::CeresFrameProblem>& problem = workspace_->ceres_;
  if (problem == nullptr || !problem->Rebind(energy_, secant)) {
    problem.reset();  // Freed before the next is built: one in memory at a time.
    problem = std::make_unique<internal::CeresFrameProblem>(
        energy_, secant, FrameCostFunctions::Layout::kPerGaussian);
    ++workspace_->problems_built_;
  }
  problem->Solve(options_, clock, k, summary);
}

SolverSummary FrameSolver::Solve(Eigen::VectorXd* k) {
  Require(k->size() == energy_->num_parameters(), "solver", "k has the wrong size");
  const double k_max = energy_->layout().bound;
  *k = k->cwiseMax(-k_max).cwiseMin(k_max);
  SolverSummary summary;
  summary.solver = EnumToString(options_.type);
  if (options_.type == SolverType::kCeres && energy_->IsLeastSquares() && k->size() > 0) {
    // Ceres' own start and final costs are the least-squares cost, and so give E.
    const Eigen::VectorXd start = *k;
    summary.ls_cost_start = summary.ls_cost_end = std::nan("");
    SolveWithCeres(k, &summary);
    if (std::isnan(summary.ls_cost_start)) {
      summary.ls_cost_start = LeastSquaresCost(energy_, start);
      summary.ls_cost_end = LeastSquaresCost(energy_, *k);
    }
    summary.energy_start = -summary.ls_cost_start;
    summary.energy_end = -summary.ls_cost_end;
    return summary;
  }
  EvaluateEnergyAndCost(energy_, *k, &summary.energy_start, &summary.ls_cost_start);
  if (options_.type == SolverType::kCeres) {
    SolveWithCeres(k, &summary);
  } else if (options_.type == SolverType::kGradientAscent) {
    internal::SolveWithGradientAscent(*energy_, options_, k, &summary);
  } else {
    internal::SolveWithLbfgs(*energy_, options_, k, &summary);
  }
  EvaluateEnergyAndCost(energy_, *k, &summary.energy_end, &summary.ls_cost_end);
  return summary;
}

}  // namespace finecap
