// The solvers of one frame's energy (frame_energy.h). All take the same problem and report the
// same statistics, so that experiments can set them side by side:
//
//  * "ceres" (default): the least-squares form, the data terms' residual blocks plus one linear
//    residual per pair of neighbours (one residual block per surface Gaussian holding both, with
//    the data blocks of its k_s alone reduced to one row summed over the terms), with
//    hand-written Jacobians; Levenberg-Marquardt with
//    conjugate gradients on the normal equations (or a sparse Cholesky factorisation); each k_s a
//    bounded 1-D parameter block; the shared work of an evaluation done once in a
//    ceres::EvaluationCallback; a block of one parameter modelled with the secant curvature of
//    its gradient (CurvatureModel).
//  * "gradient_ascent": the paper's conditioned gradient ascent on the scalar energy: a step
//    factor per k_s that grows while the sign of its derivative repeats and shrinks when it
//    flips, with capped steps.
//  * "lbfgs": ceres::GradientProblemSolver (L-BFGS with a line search) on the scalar energy; the
//    bound |k| <= k_max through the smooth change of variables k = k_max tanh(x / k_max).
#ifndef FINECAP_SOLVER_H_
#define FINECAP_SOLVER_H_

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "finecap/energy/frame_energy.h"
#include "finecap/util/enum_names.h"
#include "finecap/util/option_fields.h"

namespace finecap {

// Which solver maximises the energy (the list above).
enum class SolverType { kCeres, kGradientAscent, kLbfgs };
const std::vector<EnumName<SolverType>>& EnumNames(SolverType);

// Ceres' trust-region strategy (ceres::TrustRegionStrategyType).
enum class TrustRegionType { kLevenbergMarquardt, kDogleg };
const std::vector<EnumName<TrustRegionType>>& EnumNames(TrustRegionType);

// Ceres' linear solver (ceres::LinearSolverType): sparse Cholesky of the normal equations
// (SuiteSparse), conjugate gradients on them (inexact steps), or dense QR (tiny problems only).
enum class LinearSolverType { kSparseNormalCholesky, kCgnr, kDenseQr };
const std::vector<EnumName<LinearSolverType>>& EnumNames(LinearSolverType);

// Ceres only: the curvature of the model of a similarity block of one parameter. Gauss-Newton's
// J^T J, or the secant of the block's gradient between its last two evaluations, held within a
// factor of J^T J (ceres_cost_functions.h, ReducedDataBlockCost).
enum class CurvatureModel { kGaussNewton, kSecant };
const std::vector<EnumName<CurvatureModel>>& EnumNames(CurvatureModel);

// The solver's options. The fields but num_threads are documented where Fields() declares them
// (docs/configuration.md: solver); the comments below add what the documentation does not say.
struct SolverOptions {
  SolverType type = SolverType::kCeres;
  int max_iterations = 50;
  // 1e-3: on synth_skirt, Ceres reaches within 0.01 mm of its 1e-6 result in 5 iterations
  // instead of 32. Ceres counts only the steps it takes: a rejected step's change says nothing of
  // convergence.
  double function_tolerance = 1e-3;
  // Threads of Ceres' evaluation and linear algebra; 0 = all cores (the config's runtime.threads).
  int num_threads = 0;
  // num_threads, with 0 resolved to the machine's cores (at least one).
  int Threads() const;

  TrustRegionType trust_region = TrustRegionType::kLevenbergMarquardt;
  // Conjugate gradients: the normal equations are diagonal but for the regulariser, so a few
  // products solve them to the accuracy the step needs, at a fifth of the time of SuiteSparse's
  // factorisation on synth_skirt and to the same error on every capture measured
  // (docs/measurements.md, "Where a frame's time goes").
  LinearSolverType linear_solver = LinearSolverType::kCgnr;
  // Secant: the consensus energy curves less than J^T J says (Ceres' steps gained 1.2-1.6 times
  // what the model predicted), and with the secant Ceres ends nearer the energy's optimum for the
  // same evaluations (docs/method.md, "Solvers").
  CurvatureModel curvature = CurvatureModel::kSecant;

  // The step factors are scaled from it. A refinement makes it follow from the scene unless set
  // (RefineOptions::scene_lengths), as max_step.
  double initial_step = 0.0005;
  double step_growth = 1.2;
  double step_shrink = 0.5;
  double max_step = 0.002;

  static const OptionFields<SolverOptions>& Fields();  // option_fields.h
  void Check() const;
};

// One row of a solver's convergence trace.
struct SolverIteration {
  int iteration = 0;
  double energy = 0.0;   // E of the configured energy.
  double seconds = 0.0;  // Since the start of the solve.
};

struct SolverSummary {
  std::string solver;         // The name of SolverOptions::type.
  double energy_start = 0.0;  // E = E_sim - w_reg E_reg of the configured energy.
  double energy_end = 0.0;
  double ls_cost_start = 0.0;  // 1/2 sum of squared residuals of the least-squares form.
  double ls_cost_end = 0.0;
  int iterations = 0;
  int evaluations = 0;
  double seconds = 0.0;
  double seconds_evaluation = 0.0;     // Residuals, Jacobians, energies and gradients.
  double seconds_linear_solver = 0.0;  // Ceres only.
  // Ceres only: of seconds_evaluation, the data terms' work shared by their residual blocks at
  // each new point (BlockSummaries::PrepareBlockSummaries, all threads); the rest is Ceres' own
  // pass over the residual blocks.
  double seconds_similarity = 0.0;
  std::string termination;  // Why the solver stopped.
  std::vector<SolverIteration> trace;

  // Adds `more`'s iterations, evaluations and times: a further pass or level of the same frame.
  void AddWork(const SolverSummary& more);
};

// Maximises the energy over k (one entry per surface Gaussian, metres), starting from *k.
SolverSummary Solve(FrameEnergy* energy, const SolverOptions& options, Eigen::VectorXd* k);

namespace internal {
class CeresFrameProblem;
}  // namespace internal

// What the Ceres solver keeps from one frame to the next: its problem (cost functions, residual
// and parameter blocks), which the next frame's energy takes over when its least-squares form has
// the same structure (the same surface Gaussians, pairs of neighbours, k_max and curvature model,
// and no similarity block of several parameters), as the frames of a sequence at one level of
// detail have. Building and freeing the problem took ~10 ms of each synth_skirt frame, on the
// solving thread. Hand it to one FrameSolver at a time; it holds the last problem until it is
// destroyed.
class SolverWorkspace {
 public:
  SolverWorkspace();
  ~SolverWorkspace();
  SolverWorkspace(const SolverWorkspace&) = delete;
  SolverWorkspace& operator=(const SolverWorkspace&) = delete;

  // How many Ceres problems have been built in it: a problem taken over is not counted again.
  int problems_built() const { return problems_built_; }

 private:
  friend class FrameSolver;
  std::unique_ptr<internal::CeresFrameProblem> ceres_;
  int problems_built_ = 0;
};

// Solve, for one frame's energy solved more than once: the consensus similarity's passes, each
// after the energy's patch shape has changed. Ceres' problem is built at the first solve and kept
// in the workspace for the next ones, and for the next frame's solver given the same workspace,
// where Solve would build and free it every time; each solve takes the same steps as Solve. The
// other solvers keep nothing.
//
// Between the solves of one solver the energy's values may change, not its structure: the same
// residual blocks, regulariser, prior and k_max. `energy` and `workspace` must outlive the solver;
// without a workspace it keeps one of its own.
class FrameSolver {
 public:
  FrameSolver(FrameEnergy* energy, const SolverOptions& options,
              SolverWorkspace* workspace = nullptr);
  ~FrameSolver();
  FrameSolver(const FrameSolver&) = delete;
  FrameSolver& operator=(const FrameSolver&) = delete;

  // As Solve(energy, options, k).
  SolverSummary Solve(Eigen::VectorXd* k);

 private:
  // The Ceres solve of *k into *summary, building the problem first where needed.
  void SolveWithCeres(Eigen::VectorXd* k, SolverSummary* summary);

  FrameEnergy* energy_;
  SolverOptions options_;
  SolverWorkspace own_workspace_;
  SolverWorkspace* workspace_;
};

// 1/2 sum of squared residuals of the least-squares form at k (similarity and regulariser).
double LeastSquaresCost(FrameEnergy* energy, const Eigen::VectorXd& k);

// The energy E and the least-squares cost at k, with one evaluation of the similarity when it
// is a least-squares term (E = -cost), two otherwise.
void EvaluateEnergyAndCost(FrameEnergy* energy, const Eigen::VectorXd& k, double* energy_value,
                           double* cost);

}  // namespace finecap

#endif  // FINECAP_SOLVER_H_
