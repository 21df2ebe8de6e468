// What the two consensus similarities (consensus_similarity.h, pixel_consensus_similarity.h)
// share: the colours of one patch in each camera that sees it turned into residuals that ask the
// cameras to agree, and Cauchy's robust loss on a patch's sum of squares. Internal to the energy.
#ifndef FINECAP_SRC_ENERGY_PATCH_AGREEMENT_H_
#define FINECAP_SRC_ENERGY_PATCH_AGREEMENT_H_

#include <Eigen/Core>

#include "finecap/energy/similarity.h"

namespace finecap {
namespace internal {

// Normalises, in place, the colours q of a patch in one camera (n members of three channels):
// z_m = (q_m - mean) / deviation with deviation = sqrt(variance + floor^2), the mean per channel
// and the variance per channel or, when `pooled`, over all three channels (one gain for the
// camera); and, when `dq` is not null, turns dq/dk into dz/dk:
// dz_m/dk = (dq_m/dk - mean dq/dk - z_m <z, dq/dk>) / deviation, where <z, dq/dk> is the mean
// over the patch (and the channels, when pooled) of z_j dq_j/dk.
void Normalise(int n, double floor, bool pooled, double* q, double* dq);

// Turns, in place, the colours of a patch of n members in `num_cameras` cameras (camera after
// camera, member after member, channel after channel) and, when `jacobian` is not null, their
// k-derivatives into the consensus residuals before the robust loss: each camera's colours
// normalised (Normalise), then each against the cameras' mean, times `weight` per channel.
void AgreementResiduals(int n, int num_cameras, double floor, bool pooled,
                        const Eigen::Vector3d& weight, double* residuals, double* jacobian);

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
SimilarityTerm::BlockSummary Robustify(double c2, const SimilarityTerm::BlockSummary& plain,
                                       bool with_derivatives);

}  // namespace internal
}  // namespace finecap

#endif  // FINECAP_SRC_ENERGY_PATCH_AGREEMENT_H_
