// A similarity that peaks at the true surface: each surface Gaussian's colour against the colour
// the image shows around its projection, in closed form.
//
// In camera c, the image around the projection of surface Gaussian s, seen through the Gaussian's
// own footprint, is the overlap-weighted mean of the image Gaussians' colours,
//
//   p_sc(k_s) = sum_i E_is eta_i / sum_i E_is      (E_is: gaussian_overlap.h, no colour weight),
//
// i.e. the image model blurred by the projected surface Gaussian and read at its centre: a
// splatting renderer run backwards, evaluated at the surface Gaussian instead of at the patch.
// The residual r_sc = (p_sc - eta_s) / sqrt(n_c) is a 3-vector per visible (s, c), and
//
//   E_sim = -1/2 sum_c sum_s |r_sc|^2.
//
// Why this instead of the paper's E_sim: the paper's min() clamp rewards an even coverage of the
// image by projected Gaussians, which folds disturb whichever way they bend, so its optimum lies
// at a flatter surface than the truth. Here there is no coverage term at all: each residual only
// asks whether the colour at the projected point agrees, which it does where the Gaussian sits on
// the true surface. Each residual depends on one k_s only, so the least-squares normal equations
// are diagonal but for the regulariser, and cheap to factor. Occlusion is handled, as in the
// paper, by evaluating each surface Gaussian only in the cameras that see it.
#ifndef FINECAP_SURFACE_COLOR_SIMILARITY_H_
#define FINECAP_SURFACE_COLOR_SIMILARITY_H_

#include <vector>

#include "finecap/energy/data_term.h"
#include "finecap/model/gaussian_overlap.h"
#include "finecap/model/surface_gaussians.h"

namespace finecap {

// p_sc at displacement k of the surface Gaussian in row `row` of `view`'s pair list, over the
// pairs of that row (with `reach_sigmas` > 0, over those within that many combined standard
// deviations of it at k), and, when `derivative` is not null, dp_sc/dk. Where no image Gaussian
// is in reach the colour tends to `fallback`.
Eigen::Vector3d ImageColorOfPairs(const EnergyView& view, const SurfaceGaussians& surface, int row,
                                  double k, OverlapForm form, const Eigen::Vector3d& fallback,
                                  Eigen::Vector3d* derivative, double reach_sigmas = 0.0);

class SurfaceColorSimilarity : public SummarisedDataTerm {
 public:
  // `views` must have been built without colour weights (PairOptions::color_cutoff <= 0); both
  // arguments must outlive this object.
  SurfaceColorSimilarity(const SurfaceGaussians& surface, const std::vector<EnergyView>& views,
                         OverlapForm form);

  double Evaluate(const Eigen::VectorXd& k, Eigen::VectorXd* gradient) const override;
  const std::vector<ResidualBlock>& residual_blocks() const override { return blocks_; }
  void PrepareResiduals(const Eigen::VectorXd& k, bool with_jacobians) override;
  void BlockResiduals(int block, double* residuals, double* jacobian) const override;
  bool IsLeastSquares() const override { return true; }

  // The residual r_sc of surface Gaussian `row` of `camera`'s pair list, and dr_sc/dk_s.
  void Residual(int camera, int row, double k, Eigen::Vector3d* residual,
                Eigen::Vector3d* derivative) const;

 private:
  const SurfaceGaussians& surface_;
  const std::vector<EnergyView>& views_;
  OverlapForm form_;
  double scale_;  // 1 / sqrt(n_c).

  // Block b belongs to surface Gaussian blocks_[b].parameters[0]; its residuals are those of the
  // (camera, row) entries observations_[observation_begin_[b] ..).
  std::vector<ResidualBlock> blocks_;
  std::vector<int> observation_begin_;
  std::vector<std::pair<int, int>> observations_;
  std::vector<Eigen::Vector3d> residuals_, derivatives_;  // Per observation.
};

}  // namespace finecap

#endif  // FINECAP_SURFACE_COLOR_SIMILARITY_H_
