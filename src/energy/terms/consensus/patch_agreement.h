// What the two consensus similarities (consensus_similarity.h, pixel_consensus_similarity.h)
// share: the colours of one patch in each camera that sees it turned into residuals that ask the
// cameras to agree, and Cauchy's robust loss on a patch's sum of squares. Internal to the energy.
#ifndef FINECAP_SRC_ENERGY_PATCH_AGREEMENT_H_
#define FINECAP_SRC_ENERGY_PATCH_AGREEMENT_H_

#include <vector>

#include <Eigen/Core>

#include "finecap/energy/data_term.h"
#include "finecap/energy/energy_options.h"
#include "finecap/energy/regularizer.h"

namespace finecap {
namespace internal {

// Normalises, in place, the colours q of a patch in one camera (n members of three channels):
// z_m = (q_m - mean) / deviation with deviation = sqrt(variance + floor^2), the mean per channel
// and the variance per channel or, when `pooled`, over all three channels (one gain for the
// camera); and, when `dq` is not null, turns dq/dk into dz/dk:
// dz_m/dk = (dq_m/dk - mean dq/dk - z_m <z, dq/dk>) / deviation, where <z, dq/dk> is the mean
// over the patch (and the channels, when pooled) of z_j dq_j/dk.
void Normalise(int n, double floor, bool pooled, double* q, double* dq);
// Normalise in two halves, for colours with several derivatives: the colours, in place, leaving
// the inverse deviation of each channel in inverse_deviation[3]; then one derivative dq/dk, in
// place, from the normalised colours z and those inverse deviations.
void NormaliseColors(int n, double floor, bool pooled, double* q, double* inverse_deviation);
void NormaliseDerivative(int n, bool pooled, const double* z, const double* inverse_deviation,
                         double* dq);

// Each member's values in a patch of n members seen by `num_cameras` cameras (laid out as
// AgreementResiduals' colours) against the cameras' mean, times `weight` per channel, in place.
// With `camera_weights` (one per camera, null: all 1) the mean is weighted by them and camera a's
// values are also scaled by the root of its weight: its squared residuals count that many times.
void AgainstCameraMean(int n, int num_cameras, const Eigen::Vector3d& weight, double* values,
                       const double* camera_weights = nullptr);

// Turns, in place, the colours of a patch of n members in `num_cameras` cameras (camera after
// camera, member after member, channel after channel) and, when `jacobian` is not null, their
// k-derivatives into the consensus residuals before the robust loss: each camera's colours
// normalised (Normalise), then each against the cameras' mean, times `weight` per channel
// (AgainstCameraMean, with `camera_weights` as there).
void AgreementResiduals(int n, int num_cameras, double floor, bool pooled,
                        const Eigen::Vector3d& weight, double* residuals, double* jacobian,
                        const double* camera_weights = nullptr);

// The weight of a camera in a patch it sees at `view_cosine` (Camera::ViewCosine at the patch's
// vertex), before the patch's weights are taken relative to their mean:
// ConsensusOptions::view_cosine_power of its absolute value, kept above a grazing view's.
double ViewWeight(double view_cosine, double power);

// The per-channel root mean variance over its cameras of a patch's colours (laid out as above).
Eigen::Vector3d PatchContrast(int n, int num_cameras, const double* colors);

// The scale c2 of Cauchy's loss of a patch of n members seen by `num_cameras` cameras, residual
// weights `weight`: `fraction` of the disagreement of unrelated patches (each normalised channel
// has unit variance, so sum_m |z_m - mean_c z_m|^2 is about 3 n (n_c - 1) for them).
double AgreementLossScale(int n, int num_cameras, const Eigen::Vector3d& weight, double fraction);

// Scales a block's residuals r (and their derivatives dr/dk, when given) by Cauchy's loss of
// scale c2 (none when c2 <= 0): r' = alpha r with alpha = sqrt(rho(s) / s), s = |r|^2,
// rho(s) = c2 log(1 + s / c2), so that |r'|^2 = rho(s).
void Robustify(double c2, int num_residuals, double* residuals, double* jacobian);

// The summary of a block's residuals after Robustify from that of its residuals before it,
// without either.
BlockSummary Robustify(double c2, const BlockSummary& plain, bool with_derivatives);

// The same for a block of several unknowns, in place: its sum of squares s, gradient J^T r and
// Gauss-Newton matrix J^T J (when `curvature` is not null) after the loss, from those before it.
void Robustify(double c2, double* squared_norm, Eigen::VectorXd* gradient,
               Eigen::MatrixXd* curvature);

}  // namespace internal

// A similarity of patches that must agree across the cameras that see them, one block per patch
// and one parameter per block (the k of the surface Gaussian the patch moves with): the
// residuals, robust loss, block summaries and costs of both consensus similarities. A derived
// term says where a patch's colours come from (PatchColors), adds its patches (AddPatch) and then
// weighs them (WeighPatches).
//
// Between two passes of the solver (PassHook) its patches take the shape of the surface the pass
// found, smoothed over the mesh neighbours: the window's displacement, not each member's noise
// about it (ConsensusOptions::shape_smoothing_rounds).
class PatchAgreementTerm : public SummarisedDataTerm, public PassHook {
 public:
  double Evaluate(const Eigen::VectorXd& k, Eigen::VectorXd* gradient) const override;
  const std::vector<ResidualBlock>& residual_blocks() const override { return blocks_; }
  void PrepareResiduals(const Eigen::VectorXd& k, bool with_jacobians) override;
  void BlockResiduals(int block, double* residuals, double* jacobian) const override;
  // Each block's summary straight from its residuals before the robust loss, without storing
  // them, the loss applied to the sums.
  void PrepareBlockSummaries(const Eigen::VectorXd& k) override;
  // Each block's sum of squares without storing its residuals.
  void BlockCosts(const Eigen::VectorXd& k, std::vector<double>* costs) override;
  // Block by block without storing the residuals (a frame's detail stage has millions): the
  // same sums as DataTerm's, in the same order.
  Eigen::VectorXd GaussNewtonDiagonal(const Eigen::VectorXd& k) override;
  bool IsLeastSquares() const override { return true; }
  bool ReadsPairLists() const override { return false; }
  PassHook* pass_hook() override { return this; }
  // Shapes the patches like `k`, smoothed over the neighbours given with SmoothShapesOver.
  void EndOfPass(const Eigen::VectorXd& k) override;

  // The neighbours over which EndOfPass smooths the surface it is given; not owned, and must
  // outlive the term. Without them the shape is the surface as it is.
  void SmoothShapesOver(const Regularizer* neighbours) { neighbours_ = neighbours; }
  // The shape of the patches, one displacement per surface Gaussian (zero: the input surface).
  virtual void SetPatchShape(const Eigen::VectorXd& shape) = 0;

  // The weight w_s of each block, per channel (the patch's contrast at the input surface).
  const std::vector<Eigen::Vector3d>& block_weights() const { return weights_; }

  // What a term that compares the same patches another way needs of them
  // (SurfaceConsensusSimilarity): block b's members (its own first) and cameras, the weight per
  // channel of its residuals (w_s over the root of the frame's cameras) and the scale c2 of its
  // robust loss (none when not positive).
  int PatchSize(int b) const { return patch_begin_[b + 1] - patch_begin_[b]; }
  int NumCameras(int b) const { return camera_begin_[b + 1] - camera_begin_[b]; }
  const int* Members(int b) const { return &members_[patch_begin_[b]]; }
  Eigen::Vector3d ResidualWeight(int b) const { return scale_ * weights_[b]; }
  double LossScale(int b) const;

 protected:
  // `num_cameras`: the frame's, whose square root divides every residual.
  PatchAgreementTerm(const ConsensusOptions& options, int num_cameras);

  // The colours of block b's patch in each of its cameras with the patch displaced by k (and
  // shaped), and, when `derivatives` is not null, their k-derivatives. Written camera after
  // camera, member after member, channel after channel: the order of the block's residuals.
  virtual void PatchColors(int b, double k, double* colors, double* derivatives) const = 0;

  // Adds the block of a patch moving with `parameter`: its members (its own first) and cameras,
  // and, when not empty, one weight per camera (any positive scale: they are taken relative to
  // their mean). Without weights every camera of the block counts alike; a term gives either
  // every block weights or none.
  void AddPatch(int parameter, const std::vector<int>& members, const std::vector<int>& cameras,
                const std::vector<double>& camera_weights = {});
  // Sets every block's weight from its colours at the input surface: call once every patch is
  // added and PatchColors can read them.
  void WeighPatches();

  const int* Cameras(int b) const { return &cameras_[camera_begin_[b]]; }
  // Block b's cameras' weights, mean 1 (AddPatch), or null when every camera counts alike.
  const double* CameraWeights(int b) const {
    return camera_weights_.empty() ? nullptr : &camera_weights_[camera_begin_[b]];
  }
  // Block b's summary (its derivative parts only when `with_derivatives`), with the robust loss
  // applied to the sums instead of to every residual: what the solvers and the sweep need.
  BlockSummary SummaryAt(int b, double k, bool with_derivatives) const;

  ConsensusOptions options_;
  const Regularizer* neighbours_ = nullptr;
  double scale_;  // 1 / sqrt(n_c).
  std::vector<ResidualBlock> blocks_;
  std::vector<Eigen::Vector3d> weights_;

 private:
  // The residuals of block b at displacement k of its patch before the robust loss, and, when
  // `jacobian` is not null, their derivatives.
  void PlainResiduals(int b, double k, double* residuals, double* jacobian) const;

  // Block b's members are members_[patch_begin_[b] ..), its cameras cameras_[camera_begin_[b] ..).
  std::vector<int> patch_begin_ = {0}, members_, camera_begin_ = {0}, cameras_;
  // Per entry of cameras_, that camera's weight in its block (CameraWeights); empty when every
  // camera counts alike.
  std::vector<double> camera_weights_;
  // PrepareResiduals' results; block b's residuals and derivatives from residual_begin_[b].
  std::vector<long> residual_begin_ = {0};
  std::vector<double> residuals_, jacobians_;
};

}  // namespace finecap

#endif  // FINECAP_SRC_ENERGY_PATCH_AGREEMENT_H_
