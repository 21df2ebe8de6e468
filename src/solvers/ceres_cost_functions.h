// The Ceres pieces of the least-squares form of the energy (solver.h), with hand-written
// Jacobians: one cost function per surface Gaussian for its similarity block of one parameter (if
// it has one), its prior and its share of the regulariser, one for what of those similarity
// blocks no step can reduce, one per similarity block of several parameters, and the evaluation
// callback that computes the similarity's residuals once per evaluation point for all blocks.
#ifndef FINECAP_CERES_COST_FUNCTIONS_H_
#define FINECAP_CERES_COST_FUNCTIONS_H_

#include <deque>
#include <memory>
#include <vector>

#include <ceres/cost_function.h>
#include <ceres/evaluation_callback.h>
#include <ceres/problem.h>
#include <Eigen/Core>

#include "finecap/energy/frame_energy.h"
#include "finecap/energy/similarity.h"

namespace finecap {

class GaussianModelRows;

// Calls SimilarityTerm::PrepareBlockSummaries when every block of the term has one parameter
// (ReducedSimilarityBlockCost needs no more of them), else its default implementation, which
// prepares the residuals with Jacobians too (the paper's term mixes blocks of one parameter and
// of several), at every evaluation point that differs from the last one prepared; and, once a
// point when Ceres asks for Jacobians there, the rows of GaussianModelRows given with
// PrepareRowsToo. `k` is the vector whose entries are the problem's parameter blocks: Ceres has
// written the point there when it calls. Time spent is added to *seconds.
class SharedEvaluationCallback : public ceres::EvaluationCallback {
 public:
  SharedEvaluationCallback(SimilarityTerm* term, const Eigen::VectorXd* k, double* seconds);
  void PrepareForEvaluation(bool evaluate_jacobians, bool new_evaluation_point) override;
  // Forgets the point prepared last: the term has changed since (a further pass's patch shape),
  // and its preparation at that point no longer holds.
  void Forget() {
    prepared_.resize(0);
    rows_prepared_ = false;
  }
  // Also prepares `rows` (not owned; null for none) wherever Jacobians are evaluated.
  void PrepareRowsToo(GaussianModelRows* rows) { rows_ = rows; }
  // Prepares `term` from now on instead, forgetting the point prepared last.
  void Rebind(SimilarityTerm* term);

 private:
  SimilarityTerm* term_ = nullptr;
  const Eigen::VectorXd* k_;
  double* seconds_;
  bool summaries_only_ = true;
  Eigen::VectorXd prepared_;  // The point of the last preparation (empty before the first).
  GaussianModelRows* rows_ = nullptr;
  bool rows_prepared_ = false;  // At prepared_.
};

// Residual block `block` of the similarity, one 1-D parameter block per k_s it depends on. Its
// values are those of the last SharedEvaluationCallback preparation.
class SimilarityBlockCost : public ceres::CostFunction {
 public:
  SimilarityBlockCost(const SimilarityTerm& term, int block);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 protected:
  const SimilarityTerm& term_;
  int block_;
};

// The curvature a similarity block of one parameter is modelled with (ReducedSimilarityBlockCost):
// J^T J, or with `secant` the secant of the block's gradient between its last two evaluations with
// Jacobians, held within [kMinSecantFactor, kMaxSecantFactor] J^T J.
class BlockCurvature {
 public:
  static constexpr double kMinSecantFactor = 0.3;
  static constexpr double kMaxSecantFactor = 3.0;

  // The curvature at k, recording k and the summary's gradient for the next call.
  double At(double k, const SimilarityTerm::BlockSummary& summary, bool secant);
  // Forgets the history: gradients of a term that has changed since say nothing of the new one.
  void Forget() { has_last_ = false; }

 private:
  bool has_last_ = false;
  double last_k_ = 0.0, last_gradient_ = 0.0;
};

// The two residuals of a reduced similarity block of one parameter at k, a point with this
// summary, and their Jacobian in k's column (ReducedSimilarityBlockCost), its curvature modelled by
// `curvature`. `jacobians` as Ceres passes them: null for the cost alone (the residuals are then
// (|r|, 0) and the history is left as it is), else its first column, which may be null.
void ReducedOneParameterRows(const SimilarityTerm::BlockSummary& summary, double k, bool secant,
                             BlockCurvature* curvature, double* residuals, double** jacobians);

// The same residual block, reduced for the solver to at most p + 1 residuals for its p
// parameters (two for one parameter, from SimilarityTerm::BlockSummaryOf): with J = Q R (Q with
// orthonormal columns), the residuals Q^T r and |r - Q Q^T r|, of Jacobian R and 0. Their sum of
// squares is |r|^2, their gradient J'^T r' = J^T r and their Gauss-Newton matrix J'^T J' = J^T J,
// so the linear model |r + J dk|^2 that Levenberg-Marquardt and dogleg steps are taken on is the
// same, and so is every step: exactly, up to rounding. A consensus or surface_color block of one
// Gaussian seen by 8 cameras has 3 * 8 * 7 residuals and one parameter; reduced, Ceres assembles
// and multiplies two rows instead of 168.
//
// The Jacobian returned is R, not the derivative of the residuals returned (those are not a
// differentiable function of k): check Jacobians on SimilarityBlockCost. Without Jacobians the
// residuals are (|r|, 0, ...): Ceres uses a point's residuals alone only for its cost.
//
// With `secant`, a block of one parameter models its curvature from its own history instead of
// J^T J: h = (g - g') / (k - k') for the gradients g = J^T r at its last two evaluations with
// Jacobians (k != k'), held within [kMinSecantFactor, kMaxSecantFactor] J^T J, and J^T J until
// it has two. Its residuals are then (g / sqrt(h), sqrt(|r|^2 - g^2 / h)) with Jacobian
// (sqrt(h), 0): the same cost and gradient, a model of curvature h (h is raised to g^2 / |r|^2
// where needed to keep that root real: the model never falls below zero). Why: the consensus
// energy curves less than J^T J says (on synth_skirt Ceres' steps gained 1.2-1.6 times the
// decrease its model predicted, so they were too short), and each block depends on its own k_s
// alone, so its gradient's secant measures its true curvature. A trust-region step is accepted
// by the cost it actually achieves, so a poor model costs a rejected step, never a wrong
// solution. Ceres evaluates each residual block from one thread at a time, so the history needs
// no lock.
class ReducedSimilarityBlockCost : public ceres::CostFunction {
 public:
  // The secant's bounds, as factors of J^T J. Measured on synth_skirt, its ramp, the smoothed
  // skirt and synth_noisy: [0.3, 3] ended at a lower error than Gauss-Newton on all but the ramp
  // (level there); [0.1, 10] took steps the trust region rejected, [0.5, 2] gained less.
  static constexpr double kMinSecantFactor = BlockCurvature::kMinSecantFactor;
  static constexpr double kMaxSecantFactor = BlockCurvature::kMaxSecantFactor;

  ReducedSimilarityBlockCost(const SimilarityTerm& term, int block, bool secant = false);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;
  // Forgets the secant's history: gradients of a term that has changed since do not measure the
  // curvature of the new one.
  void ForgetHistory() const { curvature_.Forget(); }

 private:
  const SimilarityTerm& term_;
  int block_;
  int num_full_residuals_;
  SimilarityBlockCost full_;  // The block as it is, for a block with nothing to reduce.
  bool secant_;
  mutable BlockCurvature curvature_;  // Ceres evaluates a block from one thread at a time.
};

// The same residual block, but preparing the term itself at the parameters it is given (the
// other k_s held at `k`): slow, independent of any callback, for checking Jacobians with
// ceres::GradientChecker.
class IsolatedSimilarityBlockCost : public SimilarityBlockCost {
 public:
  IsolatedSimilarityBlockCost(SimilarityTerm* term, int block, const Eigen::VectorXd& k);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  SimilarityTerm* mutable_term_;
  Eigen::VectorXd k_;
};

// The quadratic terms that touch one surface Gaussian s, as one residual block: its pull towards
// the input (r = sqrt(p_s) (k_s - t_s), when p_s > 0) and the regulariser's pairs assigned to it
// (r = c_j (k_s - k_j), or r = c_j k_s when the neighbour is fixed at 0, with
// c_j = 2 sqrt(w_reg T(delta_sj)) u, so that 1/2 sum r^2 = w_reg E_reg, regularizer.h). Every
// pair belongs to exactly one of its two Gaussians. One block per Gaussian instead of one per
// pair and one per prior: a third of the residual blocks of the problem for Ceres to visit and
// assemble; the residuals, and so the cost and every step, are the same.
//
// Parameter blocks: k_s first, then each free neighbour k_j in the order of `neighbours`.
class SmoothnessBlockCost : public ceres::CostFunction {
 public:
  struct Neighbour {
    int parameter = -1;  // Index of k_j among the parameter blocks (>= 1), or -1 when fixed at 0.
    double coefficient = 0.0;  // c_j.
  };
  // `prior_root` is sqrt(p_s), or 0 for no prior residual sqrt(p_s) (k_s - t_s), whose target t_s
  // is `prior_target` (FrameEnergy::prior_target).
  SmoothnessBlockCost(double prior_root, std::vector<Neighbour> neighbours, int num_free,
                      double prior_target = 0.0);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;
  // The residuals (and, unless `jacobians` is null, their rows of each parameter block's Jacobian
  // column, from row `first_row` on) of the smoothness terms with `num_neighbours` neighbours
  // from `neighbours` on.
  static void Rows(double prior_root, double prior_target, const Neighbour* neighbours,
                   int num_neighbours, int num_parameters, double const* const* parameters,
                   double* residuals, double** jacobians, int first_row);
  // How many residuals Rows writes.
  static int NumRows(double prior_root, int num_neighbours) {
    return num_neighbours + (prior_root > 0.0 ? 1 : 0);
  }

 private:
  double prior_root_;
  double prior_target_;
  std::vector<Neighbour> neighbours_;
};

// The model rows of surface Gaussians, each with its similarity block of k_s alone (if it has
// one) and its prior folded in, prepared once a point for all of them. The reduced similarity rows
// (ReducedOneParameterRows, with the secant's curvature h) and the prior's row sqrt(p_s) k_s
// together are the cost 1/2 (|r|^2 + p_s k_s^2), gradient g + p_s k_s and Gauss-Newton curvature
// h + p_s of a Gaussian; one row holds them: (g + p_s k_s) / sqrt(h + p_s), of Jacobian
// sqrt(h + p_s). What of the cost no step can reduce, |r|^2 + p_s k_s^2 less that row's square,
// is summed over all the Gaussians into one remainder (RemainderCost). The same cost, gradient
// and J^T J, so the same linear model and steps (to rounding), with one row per Gaussian instead
// of two (three with a prior): Ceres' Jacobian cells hold every row of a residual block in every
// one of its parameter blocks' columns, so the rows left out were zeros in each neighbour's cell,
// which Ceres filled, checked and multiplied in every product of the conjugate gradients. On
// synth_skirt one solve of frame 3 (BM_Solve, three alternating runs) fell from 72.6 to 66.6 ms,
// and 30 frames' CPU from 0.542 to 0.531 s a frame (medians of five alternating runs), the same
// steps and error.
class GaussianModelRows {
 public:
  GaussianModelRows(const SimilarityTerm& term, bool secant) : term_(&term), secant_(secant) {}
  // Adds surface Gaussian `parameter` (its index in k), its similarity block `block` of one
  // parameter (-1 for none: its row is then its prior's alone), its prior's curvature p_s (0 for
  // none) and target t_s (the prior is 1/2 p_s (k_s - t_s)^2); returns its index among the rows.
  int Add(int parameter, int block, double prior, double target = 0.0);
  // Reads `term` from now on; Gaussian i's block and prior are then Set anew.
  void Rebind(const SimilarityTerm& term) { term_ = &term; }
  void Set(int i, int block, double prior, double target = 0.0) {
    gaussians_[i].block = block;
    gaussians_[i].prior = prior;
    gaussians_[i].target = target;
  }
  // Every row, its Jacobian and the remainder at k, the term's block summaries prepared there;
  // with the secant, records each Gaussian's gradient for the next point's curvature.
  void Prepare(const Eigen::VectorXd& k);
  // Forgets the secant's history: gradients of a term that has changed since do not measure the
  // curvature of the new one.
  void ForgetHistories();

  // Gaussian i's cost alone at k_s = k: sqrt(|r|^2 + p_s k^2), from the current summaries.
  double Norm(int i, double k) const;
  // At the point prepared last: Gaussian i's row, its Jacobian, and the remainder's residual.
  double Row(int i) const { return gaussians_[i].row; }
  double Length(int i) const { return gaussians_[i].length; }
  double RemainderNorm() const { return remainder_norm_; }
  int size() const { return static_cast<int>(gaussians_.size()); }

 private:
  struct Gaussian {
    int parameter = -1;
    int block = -1;
    double prior = 0.0;
    double target = 0.0;
    BlockCurvature curvature;
    double row = 0.0, length = 0.0;
  };
  // The summary of Gaussian's block, zero where it has none.
  const SimilarityTerm::BlockSummary& SummaryOf(const Gaussian& gaussian) const {
    static const SimilarityTerm::BlockSummary kNone;
    return gaussian.block >= 0 ? term_->BlockSummaryOf(gaussian.block) : kNone;
  }

  const SimilarityTerm* term_;
  bool secant_;
  std::vector<Gaussian> gaussians_;
  double remainder_norm_ = 0.0;
};

// Gaussian i of GaussianModelRows and its smoothness residuals (SmoothnessBlockCost, without a
// prior: the row holds it) as one residual block: its row, of Jacobian in k_s's column alone, then
// one row per pair of neighbours. One residual block per Gaussian instead of one for its
// similarity and one for its smoothness: half the per-block work of Ceres' evaluation (preparing,
// invalidating and checking each block) and one cell fewer per Gaussian in each conjugate-gradient
// product. On synth_skirt frame 3 (one solve from k = 0, alternating with the blocks apart, ten
// times each, medians) Ceres' evaluation time fell by 10-21 % and the solve's CPU time by 7-14 %;
// the linear solver's time stayed level.
//
// Parameter blocks: those of the smoothness block, k_s first.
class SurfaceGaussianCost : public ceres::CostFunction {
 public:
  // Row i of `rows`, the smoothness residuals as SmoothnessBlockCost(0, neighbours, num_free) with
  // the `num_neighbours` neighbours from `neighbours` on; both must outlive this object.
  SurfaceGaussianCost(const GaussianModelRows& rows, int i,
                      const SmoothnessBlockCost::Neighbour* neighbours, int num_neighbours,
                      int num_free);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  // One cost function with the block's data, not one of each kind inside it: Ceres and this
  // object read the block's data at every evaluation, and a Gaussian's block is then a small
  // object and two allocations instead of 248 bytes and five (on synth_skirt frame 3, alone, five
  // runs of each in turn: Ceres' evaluation 0.129 -> 0.118 s, the solve 0.202 -> 0.193 s,
  // medians; the same steps). The neighbours live in one array for all the Gaussians
  // (FrameCostFunctions), not one allocation each.
  const GaussianModelRows& rows_;
  int index_;
  const SmoothnessBlockCost::Neighbour* neighbours_;
  int num_neighbours_;
};

// The remainder of GaussianModelRows as one residual of zero Jacobian, on one parameter block
// (Ceres' residual blocks need one): sqrt of the sum, at a point with Jacobians; 0 at a point
// evaluated for its cost alone, where each Gaussian's row holds its whole cost.
class RemainderCost : public ceres::CostFunction {
 public:
  explicit RemainderCost(const GaussianModelRows& rows);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  const GaussianModelRows& rows_;
};

// The cost functions of one solve and the residual blocks they make. The problem does not own
// them (ceres::DO_NOT_TAKE_OWNERSHIP), so Ceres keeps no reference count for each (an entry of a
// std::map per residual block, built and torn down with every problem); they must outlive the
// problem.
class FrameCostFunctions {
 public:
  // How the residual blocks are laid out: one SurfaceGaussianCost per surface Gaussian whose
  // similarity block has one parameter and their RemainderCost (the default), or every
  // similarity block and every Gaussian's smoothness block apart (kept to check that both give
  // the same steps).
  enum class Layout { kPerGaussian, kSeparate };

  // Adds the least-squares form of `energy` to `problem`, over the parameter blocks &(*k)[s],
  // each bounded by k_max. `secant`: CurvatureModel::kSecant. Once per object: its cost functions
  // read arrays that it holds. With kPerGaussian every surface Gaussian has a SurfaceGaussianCost,
  // with or without a similarity block, so that the blocks depend on the similarity's structure
  // only through its blocks of several parameters.
  void AddResidualBlocks(const FrameEnergy& energy, bool secant, Layout layout, Eigen::VectorXd* k,
                         ceres::Problem* problem);
  // Points the cost functions at `energy` instead of the one they were added for, when its
  // least-squares form has the same residual blocks: kPerGaussian, no similarity block of
  // several parameters in either, as many surface Gaussians, the same pairs of neighbours and
  // the same k_max. Returns false, changing nothing, when it has not. The similarity's residual
  // values, the priors and the pairs' weights may all differ: a sequence's frames reuse one
  // problem.
  bool Rebind(const FrameEnergy& energy);
  // Forgets every secant history (ReducedSimilarityBlockCost's and GaussianModelRows').
  void ForgetHistories();
  // The rows of the Gaussians of SurfaceGaussianCost blocks, for the callback to prepare; null
  // when there are none.
  GaussianModelRows* model_rows() { return model_rows_.get(); }

 private:
  // Adds the similarity blocks that stand alone; returns, for each surface Gaussian, the block
  // its SurfaceGaussianCost is to hold (the first of one parameter, with kPerGaussian), or -1.
  std::vector<int> AddSimilarityBlocks(const SimilarityTerm& term, bool secant, Layout layout,
                                       Eigen::VectorXd* k, ceres::Problem* problem);

  // Whether Rebind can take an energy: the layout and what its residual blocks were made of.
  bool rebindable_ = false;
  double k_max_ = 0.0;
  std::vector<int> neighbour_begin_, neighbour_other_;
  // Every SurfaceGaussianCost's neighbours, Gaussian after Gaussian.
  std::vector<SmoothnessBlockCost::Neighbour> neighbours_;
  // Elements of a deque stay where they are as it grows: the problem holds their addresses.
  std::deque<ReducedSimilarityBlockCost> similarity_;
  std::deque<SmoothnessBlockCost> smoothness_;
  std::deque<SurfaceGaussianCost> surface_gaussians_;
  std::unique_ptr<GaussianModelRows> model_rows_;
  std::unique_ptr<RemainderCost> remainder_;
};

}  // namespace finecap

#endif  // FINECAP_CERES_COST_FUNCTIONS_H_
