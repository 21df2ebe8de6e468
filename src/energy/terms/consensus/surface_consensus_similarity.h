// The consensus similarity at the images' own resolution with every sample where the refined
// mesh puts it: the second term of the detail stage, beside PixelConsensusSimilarity.
//
// PixelConsensusSimilarity moves each patch as a whole with its vertex's k (shaped like the
// surface the pass before found), so that a block depends on one unknown: a window slid along
// the normals, as plane-sweep stereo slides one. The mesh handed back is another surface: between
// the vertices it is the blend of their k, which no window was compared at. This term compares
// that mesh itself: sample j of a patch lies at the blend sum_v W_jv k_v of the k of its face's
// corners (SurfaceSamples::weights), so a vertex's k moves every sample of its faces by its share,
// and a patch's block depends on its vertex and the corners of its faces. The patches, their
// cameras, reads, contrast weights and robust loss are those of the PixelConsensusSimilarity it is
// built on.
//
// Each face lies in the patches of its three corners. With ConsensusOptions::surface_patches
// kFaceCover (the default) the term compares it through one of them: its blocks are the patches
// of a set of vertices with a corner on every face (an end on every edge where the faces are
// split only once), about a third of the patches (two thirds), which keep half to all of what
// the term gains on the captures measured, at a third of its cost (PatchOf); with kAll, through
// every patch.
//
// Why both terms, not this one alone: with the patches alone the mesh between the vertices is
// never compared, and with this term alone neighbouring vertices may move against each other
// where the images barely tell (the blend of two corners moving apart changes a sample less than
// either), which a window moving as a whole does not allow. Summed (ConsensusOptions::
// surface_weight), every capture measured gains over the patches alone (docs/measurements.md,
// 2026-12-06).
//
// A block's residuals (three per sample and camera) are reduced to what a least-squares solver
// needs of them: with s = |r|^2, g = J^T r and H = J^T J after the loss, and H (its diagonal
// raised by 1e-12 of its largest entry, as H is only semi-definite where a corner's weights are
// all but zero) = L L^T, the p + 1 rows L^T dk + L^-1 g and sqrt(s - |L^-1 g|^2), the second with
// no derivative, have the same cost, gradient and Gauss-Newton matrix (p: the block's unknowns).
// g and H are summed over the block's members and cameras rather than formed from its m x p
// Jacobian (docs/method.md, "The refined mesh itself", derives the sums). The term's residuals
// are those rows; ResidualsOfBlock gives the residuals themselves and their Jacobian.
#ifndef FINECAP_SRC_ENERGY_SURFACE_CONSENSUS_SIMILARITY_H_
#define FINECAP_SRC_ENERGY_SURFACE_CONSENSUS_SIMILARITY_H_

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "energy/terms/consensus/pixel_consensus_similarity.h"
#include "finecap/energy/data_term.h"
#include "finecap/energy/energy_options.h"
#include "finecap/energy/frame_energy.h"

namespace finecap {

class SurfaceConsensusSimilarity : public DataTerm {
 public:
  // `patches` (the patch term built on `samples`) and `samples` must outlive this term. Its sum
  // of squares is weighted by options.surface_weight.
  SurfaceConsensusSimilarity(const PixelConsensusSimilarity& patches, const SurfaceSamples& samples,
                             const ConsensusOptions& options);

  double Evaluate(const Eigen::VectorXd& k, Eigen::VectorXd* gradient) const override;
  const std::vector<ResidualBlock>& residual_blocks() const override { return blocks_; }
  void PrepareResiduals(const Eigen::VectorXd& k, bool with_jacobians) override;
  void BlockResiduals(int block, double* residuals, double* jacobian) const override;
  void BlockCosts(const Eigen::VectorXd& k, std::vector<double>* costs) override;
  Eigen::VectorXd GaussNewtonDiagonal(const Eigen::VectorXd& k) override;
  bool IsLeastSquares() const override { return true; }
  bool ReadsPairLists() const override { return false; }

  // The block of the patch term (`patches`) whose patch block `block` compares.
  int PatchOf(int block) const { return patch_of_[block]; }

  // Block `block`'s residuals r at `k`, weighted and after the robust loss (three per member,
  // camera and channel, in ReadPatch's order), and, when `jacobian` is not null, dr/dk of its
  // unknowns (one column each, in residual_blocks()[block].parameters' order): what its reduced
  // rows stand for.
  void ResidualsOfBlock(int block, const Eigen::VectorXd& k, Eigen::VectorXd* residuals,
                        Eigen::MatrixXd* jacobian) const;

 private:
  // The corners each member of block `block` is blended from, three a member: indices into the
  // block's unknowns and the member's weights on them, those past its own corners of weight 0.
  struct MemberCorners {
    std::vector<uint16_t> local;
    std::vector<double> weights;
  };
  void CornersOfMembers(int block, MemberCorners* corners) const;
  // Sets member_begin_ and corner_local_.
  void TabulateCorners();
  // Block b's colours with every sample where the mesh displaced by k puts it (its `corners`),
  // normalised per camera (`z`; the inverse deviations, 3 a camera, in `inverse_deviations`) and,
  // when `derivatives` is not null, the colours' derivatives in their own sample's displacement.
  void ReadNormalised(int block, const Eigen::VectorXd& k, const MemberCorners& corners,
                      std::vector<double>* z, std::vector<double>* derivatives,
                      std::vector<double>* inverse_deviations) const;
  // The block's residuals before the loss and the weight at k and, when `jacobian` is not null,
  // their derivatives.
  void PlainResidualsOfBlock(int block, const Eigen::VectorXd& k, Eigen::VectorXd* residuals,
                             Eigen::MatrixXd* jacobian) const;
  // The block's sum of squares before the loss and the weight, its J^T r and, when `curvature` is
  // not null, J^T J, from sums over its members and cameras instead of its Jacobian
  // (docs/method.md derives them).
  double PlainModelOfBlock(int block, const Eigen::VectorXd& k, Eigen::VectorXd* gradient,
                           Eigen::MatrixXd* curvature) const;
  // The block's weighted sum of squares after the loss and, when `gradient` is not null, its J^T r
  // and, when `curvature` is not null, J^T J.
  double BlockModel(int block, const Eigen::VectorXd& k, Eigen::VectorXd* gradient,
                    Eigen::MatrixXd* curvature) const;

  // Sets parameter_begin_ and the contributions' index over `num_unknowns` unknowns.
  void IndexContributions(int num_unknowns);
  // Per unknown, the sum of the entries of its blocks (one per block and unknown, from
  // parameter_begin_[b] in the block's order), in the order of the blocks: the same sum on any
  // number of threads.
  Eigen::VectorXd Gather(const std::vector<double>& per_block_entry, int num_unknowns) const;

  const PixelConsensusSimilarity& patches_;
  const SurfaceSamples& samples_;
  ConsensusOptions options_;
  std::vector<ResidualBlock> blocks_;
  std::vector<int> patch_of_;  // Block b reads the patch of the patches' block patch_of_[b].
  // PrepareResiduals' reduced rows from row_begin_[b] and their Jacobians (row-major) from
  // jacobian_begin_[b].
  std::vector<long> row_begin_, jacobian_begin_;
  std::vector<double> rows_, row_jacobians_;
  // Block b's unknowns are entries parameter_begin_[b] .. of a list over all blocks; unknown s's
  // entries in it are contributions_[contribution_begin_[s] ..), ascending.
  std::vector<long> parameter_begin_, contribution_begin_, contributions_;
  // Block b's members' corners as indices into its unknowns (MemberCorners::local), from
  // kMaxCorners member_begin_[b]: looked up once, not at every evaluation.
  std::vector<long> member_begin_;
  std::vector<uint16_t> corner_local_;
};

}  // namespace finecap

#endif  // FINECAP_SRC_ENERGY_SURFACE_CONSENSUS_SIMILARITY_H_
