// The similarity term E_sim of the energy, in the two forms the solvers need:
//  * a scalar to maximise, with its gradient (the paper's gradient ascent, L-BFGS);
//  * residual blocks of a least-squares problem, each depending on a few k_s, with Jacobians
//    (Ceres), such that a smaller sum of squares means a higher similarity.
// Implementations, each in its folder of src/energy/terms/ and built by the registry
// (src/energy/term_registry.cc): PaperSimilarity (paper/), SurfaceColorSimilarity
// (surface_color/), ConsensusSimilarity and PixelConsensusSimilarity (consensus/, both on
// PatchAgreementTerm, patch_agreement.h).
#ifndef FINECAP_SIMILARITY_H_
#define FINECAP_SIMILARITY_H_

#include <string>
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

class SimilarityTerm {
 public:
  // One block of residuals and the surface Gaussians (parameters k_s) it depends on.
  struct ResidualBlock {
    std::vector<int> parameters;
    int num_residuals = 0;
  };

  virtual ~SimilarityTerm() = default;

  // The similarity at `k` (one entry per surface Gaussian, metres); higher is better. When
  // `gradient` is not null it receives dE_sim/dk.
  virtual double Evaluate(const Eigen::VectorXd& k, Eigen::VectorXd* gradient) const = 0;

  virtual const std::vector<ResidualBlock>& residual_blocks() const = 0;
  // Computes every residual (and, if asked, Jacobian) at `k` once; BlockResiduals then reads
  // them, from any number of threads, until the next call.
  virtual void PrepareResiduals(const Eigen::VectorXd& k, bool with_jacobians) = 0;
  // residuals[r] for r < num_residuals; when `jacobian` is not null, jacobian[r * P + p] =
  // d residual r / d k of parameters[p], P = parameters.size().
  virtual void BlockResiduals(int block, double* residuals, double* jacobian) const = 0;

  // What a least-squares solver's linear model of a block of one parameter k_s is made of: its
  // sum of squares |r|^2, gradient J^T r and Gauss-Newton curvature J^T J.
  struct BlockSummary {
    double squared_norm = 0.0;
    double gradient = 0.0;
    double curvature = 0.0;
  };
  // Computes the BlockSummary of every block of one parameter at `k` (blocks of several are left
  // out); BlockSummaryOf then reads them, from any number of threads, until the next call.
  // BlockResiduals is not valid after it, but for this default implementation, which prepares
  // the residuals with Jacobians and sums them (a term may compute its summaries without storing
  // every residual).
  virtual void PrepareBlockSummaries(const Eigen::VectorXd& k);
  const BlockSummary& BlockSummaryOf(int block) const { return summaries_[block]; }

  // costs[b] = the sum of squares of block b's residuals at k, for every block. Prepares the
  // residuals at k (without Jacobians) and sums them; a term may know a faster way.
  virtual void BlockCosts(const Eigen::VectorXd& k, std::vector<double>* costs);
  // costs(b, j) = BlockCosts' costs[b] with all `num_parameters` k_s at displacements[j]: the
  // plane sweep's samples. BlockCosts at each displacement in turn; a term may know a faster
  // way.
  virtual void UniformBlockCosts(int num_parameters, const Eigen::VectorXd& displacements,
                                 Eigen::MatrixXd* costs);

  // True when Evaluate(k) is exactly minus half the sum of squares of the residuals at k: then
  // the least-squares cost gives the similarity too, and a solver need not evaluate both.
  virtual bool IsLeastSquares() const { return false; }

  // False when the term reads no image Gaussian ids of its views' pair lists once it is built;
  // the frame's energy then releases them (millions of pairs, a frame's largest list).
  virtual bool ReadsPairLists() const { return true; }

  // True when the term compares patches of the surface that can be shaped like a surface found
  // before (SetPatchShape), so that a further pass of the solver reads them as that surface.
  virtual bool ShapesPatches() const { return false; }
  // The shape of the patches, one displacement per surface Gaussian (zero: the input surface).
  // Does nothing unless ShapesPatches().
  virtual void SetPatchShape(const Eigen::VectorXd& /*shape*/) {}

 protected:
  // The block's summary from its residuals r and row-major Jacobian (one column), m residuals.
  static BlockSummary Summarise(const double* residuals, const double* jacobian, int m);
  std::vector<BlockSummary> summaries_;  // PrepareBlockSummaries' results, one per block.
};

}  // namespace finecap

#endif  // FINECAP_SIMILARITY_H_
