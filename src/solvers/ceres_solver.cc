// The least-squares form of the energy as a Ceres problem with hand-written Jacobians.
#include <memory>

#include <ceres/ceres.h>

#include "finecap/util/error.h"
#include "solvers/ceres_cost_functions.h"
#include "solvers/solvers_internal.h"

namespace finecap {
namespace internal {
namespace {

// Stops the solve when a step taken lowers the cost by no more than `tolerance` times the cost
// before it. Ceres' own function tolerance also judges the steps it rejects, and ended solves on
// a rejected step whose change was small, before a shorter step was tried (synth_skirt frames
// 0-3: 2.621 against 2.636 mm RMS with Gauss-Newton curvature, 14.5 evaluations per frame both;
// 2.571 against 2.583 mm with the secant, 13 both).
class StopOnSmallDecrease : public ceres::IterationCallback {
 public:
  explicit StopOnSmallDecrease(double tolerance) : tolerance_(tolerance) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& iteration) override {
    // `cost` is after the step, `cost_change` what the step took off.
    const bool converged =
        iteration.iteration > 0 && iteration.step_is_successful &&
        iteration.cost_change <= tolerance_ * (iteration.cost + iteration.cost_change);
    stopped_ = stopped_ || converged;
    return converged ? ceres::SOLVER_TERMINATE_SUCCESSFULLY : ceres::SOLVER_CONTINUE;
  }
  bool stopped() const { return stopped_; }

 private:
  double tolerance_;
  bool stopped_ = false;
};

ceres::Solver::Options MakeCeresOptions(const SolverOptions& options) {
  ceres::Solver::Options ceres_options;
  ceres_options.max_num_iterations = options.max_iterations;
  ceres_options.function_tolerance = 0.0;  // StopOnSmallDecrease instead.
  ceres_options.num_threads = options.Threads();
  ceres_options.trust_region_strategy_type =
      options.trust_region == TrustRegionType::kDogleg ? ceres::DOGLEG : ceres::LEVENBERG_MARQUARDT;
  if (options.linear_solver == LinearSolverType::kCgnr) {
    ceres_options.linear_solver_type = ceres::CGNR;
    // Conjugate gradients stop when the step's residual falls below eta times the right-hand
    // side's. Ceres' 0.1 left the surface 0.4 % further from the truth than the exact step of
    // the sparse Cholesky factorisation; at 0.01 it is level with it, for a few more products.
    ceres_options.eta = 1e-2;
  } else if (options.linear_solver == LinearSolverType::kDenseQr) {
    ceres_options.linear_solver_type = ceres::DENSE_QR;
  } else {
    ceres_options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
    ceres_options.sparse_linear_algebra_library_type = ceres::SUITE_SPARSE;
  }
  // The bounds on k are wide (k_max): a step is projected onto them, without the projected line
  // search Ceres would otherwise run, which costs a Jacobian evaluation at every candidate.
  ceres_options.max_num_line_search_step_size_iterations = 0;
  // Levenberg-Marquardt damps with diag(J^T J) and CGNR preconditions with it, so the steps do
  // not depend on the columns' scale: Ceres' scaling of every Jacobian column (its norms, then
  // the scaled copy) changed no step beyond rounding and was ~4 % of the solve's CPU.
  ceres_options.jacobi_scaling = false;
  ceres_options.logging_type = ceres::SILENT;
  return ceres_options;
}

}  // namespace

CeresFrameProblem::CeresFrameProblem(FrameEnergy* energy, bool secant,
                                     FrameCostFunctions::Layout layout)
    : secant_(secant),
      state_(Eigen::VectorXd::Zero(energy->num_parameters())),
      shared_(DataTermsOf(energy), &state_, &seconds_shared_) {
  ceres::Problem::Options problem_options;
  problem_options.evaluation_callback = &shared_;
  problem_options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  // Ceres' checks as the problem is built stay on: disable_all_safety_checks saved ~0.1 of the
  // ~11 ms that building and destroying a synth_skirt problem takes.
  problem_ = std::make_unique<ceres::Problem>(problem_options);
  cost_functions_.AddResidualBlocks(energy, secant, layout, &state_, problem_.get());
  shared_.PrepareRowsToo(cost_functions_.model_rows());
}

bool CeresFrameProblem::Rebind(FrameEnergy* energy, bool secant) {
  if (secant != secant_ || !cost_functions_.Rebind(energy)) return false;
  shared_.Rebind(DataTermsOf(energy));
  return true;
}

void CeresFrameProblem::Solve(const SolverOptions& options, const Stopwatch& clock,
                              Eigen::VectorXd* k, SolverSummary* summary) {
  Require(k->size() == state_.size(), "solver", "k does not fit the Ceres problem");
  state_ = *k;
  shared_.Forget();
  cost_functions_.ForgetHistories();
  ceres::Solver::Options ceres_options = MakeCeresOptions(options);
  TraceRecorder recorder(clock, summary);
  ceres_options.callbacks.push_back(&recorder);
  const double seconds_shared_before = seconds_shared_;
  StopOnSmallDecrease stop(options.function_tolerance);
  ceres_options.callbacks.push_back(&stop);
  ceres::Solver::Summary ceres_summary;
  ceres::Solve(ceres_options, problem_.get(), &ceres_summary);
  VLOG(1) << ceres_summary.FullReport();

  if (ceres_summary.IsSolutionUsable()) {  // Else Ceres' costs are not those of its start and end.
    summary->ls_cost_start = ceres_summary.initial_cost;
    summary->ls_cost_end = ceres_summary.final_cost;
  }
  summary->iterations = static_cast<int>(ceres_summary.iterations.size()) - 1;
  summary->evaluations = ceres_summary.num_residual_evaluations;
  summary->termination = stop.stopped()
                             ? "CONVERGENCE (function tolerance)"
                             : ceres::TerminationTypeToString(ceres_summary.termination_type);
  summary->seconds = clock.Seconds();
  summary->seconds_evaluation = ceres_summary.residual_evaluation_time_in_seconds +
                                ceres_summary.jacobian_evaluation_time_in_seconds;
  summary->seconds_linear_solver = ceres_summary.linear_solver_time_in_seconds;
  summary->seconds_similarity = seconds_shared_ - seconds_shared_before;
  *k = state_;
}

void SolveWithCeres(FrameEnergy* energy, const SolverOptions& options, Eigen::VectorXd* k,
                    SolverSummary* summary, FrameCostFunctions::Layout layout) {
  const Stopwatch clock;
  CeresFrameProblem(energy, options.curvature == CurvatureModel::kSecant, layout)
      .Solve(options, clock, k, summary);
}

}  // namespace internal
}  // namespace finecap
