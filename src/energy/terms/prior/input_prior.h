// The pull of the displacements towards the input surface as given (k_s = t_s), not in the paper:
//
//   E_prior(k) = 1/2 sum_s p_s (k_s - t_s)^2,   E = E_sim - w_reg E_reg - E_prior,
//
// with a curvature p_s per surface Gaussian and its target t_s, where the input as given lies along
// its normal (0 unless the subdivision approximates: Loop moves the input's vertices). Where a
// plain cloth shows no texture, the colour residuals do not change with k_s and only the
// regulariser decides it: it carries the displacement of the textured surroundings into the plain
// region, which can be worse than the input. So can steep views, and too few cameras: on a sparse
// rig much of the surface is seen well by one camera only. A uniform pull (energy.w_prior) prevents
// that but costs detail wherever the images do constrain k. The confidence pull
// (energy.confidence_prior) holds each Gaussian by how little the images decide it (Confidence: the
// views that see it, the texture around it), with a strength in the units of the data's own
// curvature.
#ifndef FINECAP_ENERGY_TERMS_PRIOR_INPUT_PRIOR_H_
#define FINECAP_ENERGY_TERMS_PRIOR_INPUT_PRIOR_H_

#include <functional>

#include <Eigen/Core>

#include "finecap/energy/data_term.h"
#include "finecap/energy/energy_options.h"
#include "finecap/energy/quadratic_term.h"
#include "finecap/energy/regularizer.h"
#include "finecap/model/surface_gaussians.h"

namespace finecap {

// The median of the positive entries (0 when there is none): Gaussians no camera sees carry no
// information about what a typical one is held by.
double MedianOfPositive(const Eigen::VectorXd& values);

// H_s = sum over the data term's residuals r of (dr/dk_s)^2 at `k`: the diagonal of the
// Gauss-Newton approximation of the least-squares cost's Hessian, one entry per parameter.
Eigen::VectorXd DataCurvature(DataTerm* term, const Eigen::VectorXd& k);

// How much the reference colours vary around each surface Gaussian: over the Gaussian and its
// regulariser neighbours, the median squared distance of their colours from their per-channel
// median colour (robust, so one odd colour does not make plain cloth look textured). A property
// of the cloth, not of the cameras: a Gaussian whose normal points straight at a camera moves
// little in that image as k changes (a small H_s) but still sits on texture.
Eigen::VectorXd ColorVariation(const SurfaceGaussians& surface, const Regularizer& regularizer);

// How plain the cloth is around each surface Gaussian, in [0, 1]: exp(-V_s / t) with V_s the
// colour variation and t = confidence_threshold times its median, then a morphological closing
// (one pass) and opening (confidence_opening passes) over the regulariser neighbourhoods, so that
// isolated odd Gaussians inside a plain region count as plain and plain patches narrower than the
// opening count as textured (the regulariser interpolates those well from their surroundings).
Eigen::VectorXd PlainCloth(const SurfaceGaussians& surface, const Regularizer& regularizer,
                           const EnergyOptions& options);

// The confidence c_s in [0, 1] that the images decide k_s, from the training images alone: how
// well the cameras the similarity needs see the Gaussian (SurfaceGaussians::view_confidence: how
// many, at what angles) times how textured the cloth around it is (1 - `plain_cloth`). A Gaussian
// with c_s >= 1/2 is refined with confidence. How peaked the cost is at the input (the data
// curvature) is left out: a Gaussian no patch covers is already one that too few cameras see,
// and the regulariser carries the detail of its surroundings into it, which a real capture's
// held-out views preferred (docs/measurements.md, 2026-12-05).
Eigen::VectorXd Confidence(const SurfaceGaussians& surface, const Eigen::VectorXd& plain_cloth);

// p_s = 2 w_prior u^2 + mu H (1 - c_s)^2: the uniform pull and the confidence pull, with u the
// unit scale of E_reg, mu = confidence_prior, H = `typical_data_curvature` (the median of the
// positive data curvatures: it gives the pull the data's units; called only when mu > 0) and
// c_s = `confidence` (may be empty when mu is 0).
Eigen::VectorXd PriorCurvature(const std::function<double()>& typical_data_curvature,
                               const Eigen::VectorXd& confidence, int num_parameters,
                               const EnergyOptions& options);

// E_prior as a quadratic term of the energy (quadratic_term.h): the pulls p_s of PriorCurvature
// towards t_s, where the input as given lies (SurfaceGaussians::input_offset; 0 without).
class InputPriorTerm : public QuadraticTerm {
 public:
  explicit InputPriorTerm(const TermContext& context);
  void AddPulls(Pulls* pulls) const override;

 private:
  Eigen::VectorXd curvature_;
  Eigen::VectorXd target_;
};

}  // namespace finecap

#endif  // FINECAP_ENERGY_TERMS_PRIOR_INPUT_PRIOR_H_
