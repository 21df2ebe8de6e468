// The three solver back ends behind finecap::Solve (solver.h). Each fills iterations,
// evaluations, timings, termination and trace of the summary; Solve fills the energies.
#ifndef FINECAP_SRC_SOLVERS_SOLVERS_INTERNAL_H_
#define FINECAP_SRC_SOLVERS_SOLVERS_INTERNAL_H_

#include <chrono>

#include "finecap/solver.h"

namespace finecap {
namespace internal {

void SolveWithCeres(FrameEnergy* energy, const SolverOptions& options, Eigen::VectorXd* k,
                    SolverSummary* summary);
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

}  // namespace internal
}  // namespace finecap

#endif  // FINECAP_SRC_SOLVERS_SOLVERS_INTERNAL_H_
