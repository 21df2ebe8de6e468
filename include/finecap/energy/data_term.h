// The data terms of a frame's energy: the terms that compare the surface with the images (the
// similarity E_sim of the paper and its variants). The frame's energy sums a list of them
// (frame_energy.h), as it gathers its quadratic terms (quadratic_term.h). A data term comes in
// the two forms the solvers need:
//  * a scalar to maximise, with its gradient (the paper's gradient ascent, L-BFGS);
//  * residual blocks of a least-squares problem, each depending on a few unknowns, with
//    Jacobians (Ceres), such that a smaller sum of squares means a higher value.
// Beyond these a term may offer capabilities, each an interface it returns (null when it does not
// offer it), so that a solver asks what a term can do rather than what it is:
//  * BlockSummaries: its blocks of one unknown reduced to one row summary each, which the Ceres
//    adapter sums per unknown (src/solvers/ceres_cost_functions.h) instead of taking every
//    residual of the block;
//  * SweepCosts: its blocks' costs with every unknown at the same displacement, for the plane
//    sweep that starts a solve (sweep.h);
//  * PassHook: a change of the term between two passes of the solver, from the surface the pass
//    found (the consensus' patches shaped like it).
// Implementations, each in its folder of src/energy/terms/ and built by the registry
// (src/energy/term_registry.cc): PaperSimilarity (paper/), SurfaceColorSimilarity
// (surface_color/), ConsensusSimilarity and PixelConsensusSimilarity (consensus/, both on
// PatchAgreementTerm, patch_agreement.h).
#ifndef FINECAP_ENERGY_DATA_TERM_H_
#define FINECAP_ENERGY_DATA_TERM_H_

#include <vector>

#include <Eigen/Core>

#include "finecap/geometry/camera.h"
#include "finecap/model/gaussian_pairs.h"
#include "finecap/model/image_gaussians.h"

namespace finecap {

// One camera of a frame as the energy sees it.
struct EnergyView {
  Camera camera;                          // Pinhole: the images are undistorted.
  const ImageGaussians* image = nullptr;  // Not owned; outlives the energy.
  CameraPairs pairs;
};

// What a least-squares solver's linear model of a block of one unknown k_s is made of: its sum
// of squares |r|^2, gradient J^T r and Gauss-Newton curvature J^T J. The summaries of several
// blocks of one unknown add up to the summary of the blocks stacked.
struct BlockSummary {
  double squared_norm = 0.0;
  double gradient = 0.0;
  double curvature = 0.0;
};

class BlockSummaries;
class SweepCosts;
class PassHook;

class DataTerm {
 public:
  // One block of residuals and the unknowns (indices into k) it depends on.
  struct ResidualBlock {
    std::vector<int> parameters;
    int num_residuals = 0;
  };

  virtual ~DataTerm() = default;

  // The term at `k` (one entry per unknown, metres); higher is better. When `gradient` is not
  // null it receives the term's derivative in k.
  virtual double Evaluate(const Eigen::VectorXd& k, Eigen::VectorXd* gradient) const = 0;

  virtual const std::vector<ResidualBlock>& residual_blocks() const = 0;
  // Computes every residual (and, if asked, Jacobian) at `k` once; BlockResiduals then reads
  // them, from any number of threads, until the next call.
  virtual void PrepareResiduals(const Eigen::VectorXd& k, bool with_jacobians) = 0;
  // residuals[r] for r < num_residuals; when `jacobian` is not null, jacobian[r * P + p] =
  // d residual r / d k of parameters[p], P = parameters.size().
  virtual void BlockResiduals(int block, double* residuals, double* jacobian) const = 0;

  // costs[b] = the sum of squares of block b's residuals at k, for every block. Prepares the
  // residuals at k (without Jacobians) and sums them; a term may know a faster way.
  virtual void BlockCosts(const Eigen::VectorXd& k, std::vector<double>* costs);
  // costs(b, j) = BlockCosts' costs[b] with every unknown moved by displacements[j] from `base`:
  // a term's value along a family of surfaces parallel to `base`.
  void BlockCostsAround(const Eigen::VectorXd& base, const Eigen::VectorXd& displacements,
                        Eigen::MatrixXd* costs);

  // H_s = the sum over the residuals r of (dr/dk_s)^2 at k, one entry per unknown (the diagonal
  // of the Gauss-Newton J^T J). Prepares the residuals with Jacobians
  // and sums them; a term may know a way that keeps none of them.
  virtual Eigen::VectorXd GaussNewtonDiagonal(const Eigen::VectorXd& k);

  // True when Evaluate(k) is exactly minus half the sum of squares of the residuals at k: then
  // the least-squares cost gives the term's value too, and a solver need not evaluate both.
  virtual bool IsLeastSquares() const { return false; }

  // False when the term reads no image Gaussian ids of its views' pair lists once it is built;
  // the frame's energy then releases them (millions of pairs, a frame's largest list), unless
  // another of its terms reads them.
  virtual bool ReadsPairLists() const { return true; }

  // The capabilities the term offers (see the top of this file); null for those it does not.
  // They are parts of the term: the pointers live as long as it does.
  virtual BlockSummaries* block_summaries() { return nullptr; }
  virtual SweepCosts* sweep_costs() { return nullptr; }
  virtual PassHook* pass_hook() { return nullptr; }
};

// Capability: the term's blocks of one unknown as their BlockSummary. A least-squares solver
// needs of such a block only its linear model, and a term may compute that without writing every
// residual (the consensus writes none); the Ceres adapter then sums the summaries of all the
// terms on each unknown into one row.
class BlockSummaries {
 public:
  virtual ~BlockSummaries() = default;
  // Computes the summary of every block of one unknown at `k`; BlockSummaryOf then reads them,
  // from any number of threads, until the next call. After it the residuals and Jacobians of the
  // term's blocks of several unknowns are those at `k` (BlockResiduals reads them); those of its
  // blocks of one unknown need not be.
  virtual void PrepareBlockSummaries(const Eigen::VectorXd& k) = 0;
  // Block `block`'s summary (a block of one unknown), as the last preparation left it.
  virtual const BlockSummary& BlockSummaryOf(int block) const = 0;
};

// Capability: the costs the plane sweep (sweep.h) reads, the term's value along a family of
// surfaces parallel to the input. A term whose blocks mean nothing there (one that reads another
// frame's solution, say) does not offer it and is left out of the sweep.
class SweepCosts {
 public:
  virtual ~SweepCosts() = default;
  // costs(b, j) = DataTerm::BlockCosts' costs[b] with all `num_unknowns` unknowns at
  // displacements[j], for every block b.
  virtual void UniformBlockCosts(int num_unknowns, const Eigen::VectorXd& displacements,
                                 Eigen::MatrixXd* costs) = 0;
};

// Capability: a term that changes between two passes of the solver. A pass ends at a surface,
// and such a term reads that surface to become a better model of the images near it (the
// consensus compares patches shaped like it instead of like the input surface); the next pass
// solves the changed term. The solution stays the solver's: the term changes, not k.
class PassHook {
 public:
  virtual ~PassHook() = default;
  // `k`: where the pass ended, one entry per unknown.
  virtual void EndOfPass(const Eigen::VectorXd& k) = 0;
};

// A data term that offers BlockSummaries and SweepCosts by the general means: its residuals and
// Jacobians at k summed block by block, and BlockCosts at each displacement of the sweep in turn.
// A term with a faster way overrides them.
class SummarisedDataTerm : public DataTerm, public BlockSummaries, public SweepCosts {
 public:
  BlockSummaries* block_summaries() override { return this; }
  SweepCosts* sweep_costs() override { return this; }

  // Prepares the residuals with Jacobians at k and sums each block of one unknown's.
  void PrepareBlockSummaries(const Eigen::VectorXd& k) override;
  const BlockSummary& BlockSummaryOf(int block) const override { return summaries_[block]; }
  void UniformBlockCosts(int num_unknowns, const Eigen::VectorXd& displacements,
                         Eigen::MatrixXd* costs) override;

  // The summary of a block of one unknown from its residuals r and their derivatives, m of each.
  static BlockSummary Summarise(const double* residuals, const double* jacobian, int m);

 protected:
  std::vector<BlockSummary> summaries_;  // PrepareBlockSummaries' results, one per block.
};

}  // namespace finecap

#endif  // FINECAP_ENERGY_DATA_TERM_H_
