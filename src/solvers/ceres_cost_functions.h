// The Ceres pieces of the least-squares form of a frame's energy (solver.h), with hand-written
// Jacobians: one generic adapter for any list of data terms (data_term.h). Per unknown k_s, one
// cost function holds the rows of every data term that reduces its block of k_s to a summary
// (BlockSummaries), summed, with the pulls on k_s and its share of the differences of
// neighbours; one holds what of those summaries no step can reduce; every other block (of several
// unknowns, or of a term that does not reduce) is a cost function of its own. An evaluation
// callback prepares every term once per evaluation point for all its blocks.
#ifndef FINECAP_CERES_COST_FUNCTIONS_H_
#define FINECAP_CERES_COST_FUNCTIONS_H_

#include <deque>
#include <memory>
#include <vector>

#include <ceres/cost_function.h>
#include <ceres/evaluation_callback.h>
#include <ceres/problem.h>
#include <Eigen/Core>

#include "finecap/energy/data_term.h"
#include "finecap/energy/frame_energy.h"

namespace finecap {

class GaussianModelRows;

// Prepares each data term at every evaluation point that differs from the last one prepared:
// its block summaries (BlockSummaries::PrepareBlockSummaries, which leaves the residuals of its
// blocks of several unknowns prepared too) when it offers them, else its residuals with
// Jacobians; and, once a point when Ceres asks for Jacobians there, the rows of GaussianModelRows
// given with PrepareRowsToo. `k` is the vector whose entries are the problem's parameter blocks:
// Ceres has written the point there when it calls. Time spent is added to *seconds.
class SharedEvaluationCallback : public ceres::EvaluationCallback {
 public:
  SharedEvaluationCallback(std::vector<DataTerm*> terms, const Eigen::VectorXd* k, double* seconds);
  void PrepareForEvaluation(bool evaluate_jacobians, bool new_evaluation_point) override;
  // Forgets the point prepared last: a term has changed since (PassHook), and its preparation at
  // that point no longer holds.
  void Forget() {
    prepared_.resize(0);
    rows_prepared_ = false;
  }
  // Also prepares `rows` (not owned; null for none) wherever Jacobians are evaluated.
  void PrepareRowsToo(GaussianModelRows* rows) { rows_ = rows; }
  // Prepares `terms` from now on instead, forgetting the point prepared last.
  void Rebind(std::vector<DataTerm*> terms);

 private:
  std::vector<DataTerm*> terms_;
  const Eigen::VectorXd* k_;
  double* seconds_;
  Eigen::VectorXd prepared_;  // The point of the last preparation (empty before the first).
  GaussianModelRows* rows_ = nullptr;
  bool rows_prepared_ = false;  // At prepared_.
};

// The data terms of `energy`, in its order.
std::vector<DataTerm*> DataTermsOf(FrameEnergy* energy);

// Residual block `block` of a data term, as it is, one 1-D parameter block per k_s it depends on.
// Its values are those of the last SharedEvaluationCallback preparation.
class DataBlockCost : public ceres::CostFunction {
 public:
  DataBlockCost(const DataTerm& term, int block);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 protected:
  const DataTerm& term_;
  int block_;
};

// The curvature a data block of one parameter is modelled with (ReducedDataBlockCost):
// J^T J, or with `secant` the secant of the block's gradient between its last two evaluations with
// Jacobians, held within [kMinSecantFactor, kMaxSecantFactor] J^T J.
class BlockCurvature {
 public:
  static constexpr double kMinSecantFactor = 0.3;
  static constexpr double kMaxSecantFactor = 3.0;

  // The curvature at k, recording k and the summary's gradient for the next call.
  double At(double k, const BlockSummary& summary, bool secant);
  // Forgets the history: gradients of a term that has changed since say nothing of the new one.
  void Forget() { has_last_ = false; }

 private:
  bool has_last_ = false;
  double last_k_ = 0.0, last_gradient_ = 0.0;
};

// The two residuals of a reduced data block of one parameter at k, a point with this
// summary, and their Jacobian in k's column (ReducedDataBlockCost), its curvature modelled by
// `curvature`. `jacobians` as Ceres passes them: null for the cost alone (the residuals are then
// (|r|, 0) and the history is left as it is), else its first column, which may be null.
void ReducedOneParameterRows(const BlockSummary& summary, double k, bool secant,
                             BlockCurvature* curvature, double* residuals, double** jacobians);

// The same residual block, reduced for the solver to at most p + 1 residuals for its p
// parameters (two for one parameter, from BlockSummaries::BlockSummaryOf): with J = Q R (Q with
// orthonormal columns), the residuals Q^T r and |r - Q Q^T r|, of Jacobian R and 0. Their sum of
// squares is |r|^2, their gradient J'^T r' = J^T r and their Gauss-Newton matrix J'^T J' = J^T J,
// so the linear model |r + J dk|^2 that Levenberg-Marquardt and dogleg steps are taken on is the
// same, and so is every step: exactly, up to rounding. A consensus or surface_color block of one
// Gaussian seen by 8 cameras has 3 * 8 * 7 residuals and one parameter; reduced, Ceres assembles
// and multiplies two rows instead of 168.
//
// The Jacobian returned is R, not the derivative of the residuals returned (those are not a
// differentiable function of k): check Jacobians on DataBlockCost. Without Jacobians the
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
class ReducedDataBlockCost : public ceres::CostFunction {
 public:
  // The secant's bounds, as factors of J^T J. Measured on synth_skirt, its ramp, the smoothed
  // skirt and synth_noisy: [0.3, 3] ended at a lower error than Gauss-Newton on all but the ramp
  // (level there); [0.1, 10] took steps the trust region rejected, [0.5, 2] gained less.
  static constexpr double kMinSecantFactor = BlockCurvature::kMinSecantFactor;
  static constexpr double kMaxSecantFactor = BlockCurvature::kMaxSecantFactor;

  // `summaries`: the term's (BlockSummaries), which a block of one parameter reads; null for a
  // term that offers none, whose blocks of one parameter are then not to be reduced.
  ReducedDataBlockCost(const DataTerm& term, const BlockSummaries* summaries, int block,
                       bool secant = false);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;
  // Forgets the secant's history: gradients of a term that has changed since do not measure the
  // curvature of the new one.
  void ForgetHistory() const { curvature_.Forget(); }

 private:
  const DataTerm& term_;
  const BlockSummaries* summaries_;
  int block_;
  int num_full_residuals_;
  DataBlockCost full_;  // The block as it is, for a block with nothing to reduce.
  bool secant_;
  mutable BlockCurvature curvature_;  // Ceres evaluates a block from one thread at a time.
};

// The same residual block, but preparing the term itself at the parameters it is given (the
// other k_s held at `k`): slow, independent of any callback, for checking Jacobians with
// ceres::GradientChecker.
class IsolatedDataBlockCost : public DataBlockCost {
 public:
  IsolatedDataBlockCost(DataTerm* term, int block, const Eigen::VectorXd& k);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  DataTerm* mutable_term_;
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

// The model rows of surface Gaussians, each with the reduced blocks of k_s alone of every data
// term (BlockSummaries), summed, and the pull on k_s folded in, prepared once a point for all of
// them. The summed summary (|r|^2, gradient g, curvature h, the secant's in place of J^T J with
// it) and the pull's row sqrt(p_s) (k_s - t_s) together are the cost 1/2 (|r|^2 + p_s d^2),
// d = k_s - t_s, gradient g + p_s d and Gauss-Newton curvature h + p_s of a Gaussian; one row
// holds them: (g + p_s d) / sqrt(h + p_s), of Jacobian sqrt(h + p_s). What of the cost no step
// can reduce, |r|^2 + p_s d^2 less that row's square, is summed over all the Gaussians into one
// remainder (RemainderCost). The same cost, gradient and J^T J as the blocks' own residuals, so
// the same linear model and steps (to rounding), with one row per Gaussian: Ceres' Jacobian cells
// hold every row of a residual block in every one of its parameter blocks' columns, so each row
// left out would be zeros in each neighbour's cell, filled and multiplied in every product of the
// conjugate gradients.
class GaussianModelRows {
 public:
  explicit GaussianModelRows(bool secant) : secant_(secant) {}
  // Adds surface Gaussian `parameter` (its index in k), with no block yet, the pull's curvature
  // p_s (0 for none) and target t_s (the pull is 1/2 p_s (k_s - t_s)^2); returns its index among
  // the rows.
  int Add(int parameter, double prior, double target = 0.0);
  // Adds block `block` of `summaries` (a block of k_s alone; not owned) to Gaussian i's row. The
  // blocks are added Gaussian after Gaussian: i is the last Gaussian given blocks, or one with
  // none yet.
  void AddBlock(int i, const BlockSummaries* summaries, int block);
  // Removes every Gaussian's blocks, keeping the Gaussians: they are then Set and given their
  // blocks anew (another frame's terms).
  void ClearBlocks();
  void Set(int i, double prior, double target = 0.0) {
    gaussians_[i].prior = prior;
    gaussians_[i].target = target;
  }
  // Every row, its Jacobian and the remainder at k, the terms' block summaries prepared there;
  // with the secant, records each Gaussian's gradient for the next point's curvature.
  void Prepare(const Eigen::VectorXd& k);
  // Forgets the secant's history: gradients of a term that has changed since do not measure the
  // curvature of the new one.
  void ForgetHistories();

  // Gaussian i's cost alone at k_s = k: sqrt(|r|^2 + p_s (k - t_s)^2), from the current summaries.
  double Norm(int i, double k) const;
  // At the point prepared last: Gaussian i's row, its Jacobian, and the remainder's residual.
  double Row(int i) const { return gaussians_[i].row; }
  double Length(int i) const { return gaussians_[i].length; }
  double RemainderNorm() const { return remainder_norm_; }
  int size() const { return static_cast<int>(gaussians_.size()); }
  // Gaussian i's blocks' summaries summed, as the terms' last preparation left them.
  BlockSummary Summary(int i) const;

 private:
  struct Block {
    const BlockSummaries* summaries = nullptr;
    int block = -1;
  };
  struct Gaussian {
    int parameter = -1;
    int first_block = 0, num_blocks = 0;  // Its blocks: blocks_[first_block ..).
    double prior = 0.0;
    double target = 0.0;
    BlockCurvature curvature;
    double row = 0.0, length = 0.0;
  };

  bool secant_;
  std::vector<Block> blocks_;
  std::vector<Gaussian> gaussians_;
  double remainder_norm_ = 0.0;
};

// Gaussian i of GaussianModelRows and its smoothness residuals (SmoothnessBlockCost, without a
// prior: the row holds it) as one residual block: its row, of Jacobian in k_s's column alone, then
// one row per pair of neighbours. One residual block per Gaussian instead of one for its data
// and one for its smoothness: half the per-block work of Ceres' evaluation (preparing,
// invalidating and checking each block) and one cell fewer per Gaussian in each conjugate-gradient
// product.
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
  // object and two allocations. The neighbours live in one array for all the Gaussians
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
  // How the residual blocks are laid out: one SurfaceGaussianCost per surface Gaussian with the
  // reduced data blocks of its k_s alone and their RemainderCost (the default), or every data
  // block and every Gaussian's smoothness block apart (kept to check that both give the same
  // steps).
  enum class Layout { kPerGaussian, kSeparate };

  // Adds the least-squares form of `energy` to `problem`, over the parameter blocks &(*k)[s],
  // each bounded by the layout's bound. `secant`: CurvatureModel::kSecant. Once per object: its
  // cost functions read arrays that it holds. With kPerGaussian every surface Gaussian has a
  // SurfaceGaussianCost, holding the first block of k_s alone of each term that offers
  // BlockSummaries, or none; every other data block stands alone: reduced
  // (ReducedDataBlockCost) when the term offers summaries or the block has several
  // parameters, else as it is (DataBlockCost).
  void AddResidualBlocks(FrameEnergy* energy, bool secant, Layout layout, Eigen::VectorXd* k,
                         ceres::Problem* problem);
  // Points the cost functions at `energy` instead of the one they were added for, when its
  // least-squares form has the same residual blocks: kPerGaussian, no data block standing alone
  // in either, as many surface Gaussians, the same pairs of neighbours and the same bound.
  // Returns false, changing nothing, when it has not. The data terms' values, the pulls and the
  // pairs' weights may all differ: a sequence's frames reuse one problem.
  bool Rebind(FrameEnergy* energy);
  // Forgets every secant history (ReducedDataBlockCost's and GaussianModelRows').
  void ForgetHistories();
  // The rows of the Gaussians of SurfaceGaussianCost blocks, for the callback to prepare; null
  // when there are none.
  GaussianModelRows* model_rows() { return model_rows_.get(); }

 private:
  // Adds the blocks of `term` that stand alone; returns, for each surface Gaussian, the block of
  // the term its SurfaceGaussianCost is to hold (the first of k_s alone, with kPerGaussian and
  // the term's summaries), or -1.
  std::vector<int> AddDataBlocks(DataTerm* term, bool secant, Layout layout, Eigen::VectorXd* k,
                                 ceres::Problem* problem);
  // For each surface Gaussian, the block of `term` of its k_s alone when every block of the term
  // is one, of one parameter, and the term offers summaries; empty otherwise.
  static std::vector<int> OneBlockPerGaussian(DataTerm* term, int num_gaussians);
  // Hands model row `row`, of surface Gaussian s, the block block_of[t][s] of each term t that
  // has one (an empty list or -1: none).
  void AddSummaryBlocks(int row, int s, const std::vector<std::vector<int>>& block_of,
                        FrameEnergy* energy);

  // Whether Rebind can take an energy: the layout and what its residual blocks were made of.
  bool rebindable_ = false;
  double k_max_ = 0.0;
  std::vector<int> neighbour_begin_, neighbour_other_;
  // Every SurfaceGaussianCost's neighbours, Gaussian after Gaussian.
  std::vector<SmoothnessBlockCost::Neighbour> neighbours_;
  // Elements of a deque stay where they are as it grows: the problem holds their addresses.
  std::deque<ReducedDataBlockCost> reduced_;
  std::deque<DataBlockCost> full_;
  std::deque<SmoothnessBlockCost> smoothness_;
  std::deque<SurfaceGaussianCost> surface_gaussians_;
  std::unique_ptr<GaussianModelRows> model_rows_;
  std::unique_ptr<RemainderCost> remainder_;
};

}  // namespace finecap

#endif  // FINECAP_CERES_COST_FUNCTIONS_H_
