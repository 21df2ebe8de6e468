// The three solver back ends behind finecap::Solve (solver.h). Each fills iterations,
// evaluations, timings, termination and trace of the summary; Solve fills the energies.
#ifndef FINECAP_SRC_SOLVERS_SOLVERS_INTERNAL_H_
#define FINECAP_SRC_SOLVERS_SOLVERS_INTERNAL_H_

#include <chrono>
#include <memory>

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

// The least-squares form of a frame's energy as a Ceres problem, built once and solved as often
// as asked: the cost functions, residual blocks and parameter blocks (on synth_skirt ~10 ms to
// build and free, on the solving thread alone) then serve every pass of the frame and, through
// Rebind, the frames after it while their problems have the same structure. Between two solves
// the energy's values may change (a pass's patch shape, another frame's images), not its
// structure: each solve forgets the point prepared last and the secant histories, so that it
// takes the steps a problem built afresh would. The parameter blocks are the entries of a vector
// of its own, into which each solve copies its start.
class CeresFrameProblem {
 public:
  // The problem of `energy`; `secant`: CurvatureModel::kSecant.
  CeresFrameProblem(FrameEnergy* energy, bool secant, FrameCostFunctions::Layout layout);
  // Takes `energy` from now on, when its problem has the structure of this one
  // (FrameCostFunctions::Rebind) and the same curvature model; returns false, changing nothing,
  // when not.
  bool Rebind(FrameEnergy* energy, bool secant);
  // Solves from *k, in place. `clock` started with the solve (before the problem was built, if it
  // was built for it); the summary's times and trace are taken against it.
  void Solve(const SolverOptions& options, const Stopwatch& clock, Eigen::VectorXd* k,
             SolverSummary* summary);

 private:
  bool secant_;
  Eigen::VectorXd state_;  // The parameter blocks.
  double seconds_shared_ = 0.0;
  SharedEvaluationCallback shared_;
  FrameCostFunctions cost_functions_;  // Outlive the problem, which does not own them.
  std::unique_ptr<ceres::Problem> problem_;
};

}  // namespace internal
}  // namespace finecap

#endif  // FINECAP_SRC_SOLVERS_SOLVERS_INTERNAL_H_
