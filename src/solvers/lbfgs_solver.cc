// L-BFGS on the scalar energy through ceres::GradientProblemSolver. The bound |k| <= k_max is
// kept by optimising x with k = k_max tanh(x / k_max), which is smooth and close to k = x near 0.
#include <cmath>

#include <ceres/gradient_problem.h>
#include <ceres/gradient_problem_solver.h>

#include "solvers/solvers_internal.h"

namespace finecap {
namespace internal {
namespace {

class NegativeEnergy : public ceres::FirstOrderFunction {
 public:
  NegativeEnergy(const FrameEnergy& energy, int* evaluations)
      : energy_(energy), k_max_(energy.layout().bound), evaluations_(evaluations) {}

  int NumParameters() const override { return energy_.num_parameters(); }

  bool Evaluate(const double* parameters, double* cost, double* gradient) const override {
    const Eigen::Map<const Eigen::VectorXd> x(parameters, NumParameters());
    const Eigen::VectorXd squashed = (x / k_max_).array().tanh();
    Eigen::VectorXd energy_gradient;
    *cost = -energy_.Evaluate(k_max_ * squashed, gradient ? &energy_gradient : nullptr);
    ++*evaluations_;
    if (gradient != nullptr) {
      const Eigen::VectorXd dk_dx = 1.0 - squashed.array().square();
      Eigen::Map<Eigen::VectorXd>(gradient, NumParameters()) =
          -(energy_gradient.array() * dk_dx.array()).matrix();
    }
    return std::isfinite(*cost);
  }

  Eigen::VectorXd ToParameters(const Eigen::VectorXd& k) const {
    // atanh of the bound itself is infinite: keep a hair inside.
    const Eigen::VectorXd ratio = (k / k_max_).cwiseMax(-1.0 + 1e-9).cwiseMin(1.0 - 1e-9);
    return k_max_ * ratio.array().atanh().matrix();
  }
  Eigen::VectorXd ToK(const Eigen::VectorXd& x) const {
    return k_max_ * (x / k_max_).array().tanh().matrix();
  }

 private:
  const FrameEnergy& energy_;
  double k_max_;
  int* evaluations_;
};

}  // namespace

void SolveWithLbfgs(const FrameEnergy& energy, const SolverOptions& options, Eigen::VectorXd* k,
                    SolverSummary* summary) {
  const Stopwatch clock;
  auto* function = new NegativeEnergy(energy, &summary->evaluations);
  const ceres::GradientProblem problem(function);  // Takes ownership.
  Eigen::VectorXd x = function->ToParameters(*k);
  ceres::GradientProblemSolver::Options solver_options;
  solver_options.line_search_direction_type = ceres::LBFGS;
  solver_options.max_num_iterations = options.max_iterations;
  solver_options.function_tolerance = options.function_tolerance;
  solver_options.logging_type = ceres::SILENT;
  TraceRecorder recorder(clock, summary);
  solver_options.callbacks.push_back(&recorder);
  ceres::GradientProblemSolver::Summary ceres_summary;
  ceres::Solve(solver_options, problem, x.data(), &ceres_summary);
  *k = function->ToK(x);
  summary->iterations = static_cast<int>(ceres_summary.iterations.size()) - 1;
  summary->termination = ceres::TerminationTypeToString(ceres_summary.termination_type);
  summary->seconds = clock.Seconds();
  summary->seconds_evaluation = ceres_summary.cost_evaluation_time_in_seconds +
                                ceres_summary.gradient_evaluation_time_in_seconds;
}

}  // namespace internal
}  // namespace finecap
