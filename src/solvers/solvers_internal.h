// The three solver back ends behind finecap::Solve (solver.h). Each fills iterations,
// evaluations, timings, termination and trace of the summary; Solve fills the energies.
#ifndef FINECAP_SRC_SOLVERS_SOLVERS_INTERNAL_H_
#define FINECAP_SRC_SOLVERS_SOLVERS_INTERNAL_H_

#include <chrono>

#include <ceres/iteration_callback.h>

#include "finecap/solvers/solver.h"
#include "solvers/ceres_cost_functions.h"

namespace finecap {
namespace internal {

// `layout`: how the residual blocks reach Ceres; the same steps either way, to rounding.
void SolveWithCeres(FrameEnergy* energy, const SolverOptions& options, Eigen::VectorXd* k,
                    SolverSummary* summary,
                    FrameCostFunctions::Layout layout = FrameCostFunctions::Layout::kPerGaussian);
void SolveWithGradientAscent(const FrameEnergy& energy, const SolverOptions& options,
                             Eigen::VectorXd* k, SolverSummary* summary);
void SolveWithLbfgs(const FrameEnergy& energy, const SolverOptions& options, Eigen::VectorXd* k,
                    SolverSummary* summary);

// Seconds since construction.
class Stopwatch {
 public:
  double Seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

 private:
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

// Records each Ceres iteration in the summary's trace. Ceres minimises a cost; the trace holds it
// negated, so that larger is better in every trace (for the colour similarity the least-squares
// cost is exactly -E, and L-BFGS minimises -E itself).
class TraceRecorder : public ceres::IterationCallback {
 public:
  TraceRecorder(const Stopwatch& clock, SolverSummary* summary)
      : clock_(clock), summary_(summary) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& iteration) override {
    summary_->trace.push_back({iteration.iteration, -iteration.cost, clock_.Seconds()});
    return ceres::SOLVER_CONTINUE;
  }

 private:
  const Stopwatch& clock_;
  SolverSummary* summary_;
};

}  // namespace internal
}  // namespace finecap

#endif  // FINECAP_SRC_SOLVERS_SOLVERS_INTERNAL_H_
