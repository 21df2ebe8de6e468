// The overlap of a projected surface Gaussian and an image Gaussian: the integral over the image
// plane of the product of two unnormalised isotropic 2D Gaussians, in closed form, and its
// derivative with respect to the displacement k of the surface Gaussian along its normal.
//
// For means m_s, m_i and standard deviations sigma_s, sigma_i (pixels), with S = sigma_s^2 +
// sigma_i^2 and d = m_i - m_s:
//
//   printed form (the paper's equation, default):  2 pi sigma_s^2 sigma_i^2 / S * exp(-|d|^2 / S)
//   exact form (the true integral):                 2 pi sigma_s^2 sigma_i^2 / S * exp(-|d|^2 /
//   (2S))
//
// Both give pi sigma^2 for a Gaussian with itself. The paper's colour weight T is applied by the
// caller, since it does not depend on k.
#ifndef FINECAP_GAUSSIAN_OVERLAP_H_
#define FINECAP_GAUSSIAN_OVERLAP_H_

#include <cmath>
#include <vector>

#include <Eigen/Core>

#include "finecap/util/enum_names.h"

namespace finecap {

// kPatch treats an image Gaussian as what it stands for, a square of side 2 sigma_i of uniform
// colour: a square's variance is sigma_i^2 / 3 per axis, so S = sigma_s^2 + sigma_i^2 / 3 and the
// exponent is the exact one, -|d|^2 / (2S). Then the overlap-weighted mean colour of the image
// Gaussians is the image blurred by the surface Gaussian (up to the squares' shape).
enum class OverlapForm { kPrinted, kExact, kPatch };
const std::vector<EnumName<OverlapForm>>& EnumNames(OverlapForm);  // printed, exact, patch.

// Where a surface Gaussian projects in one camera, and how that moves with k:
// pixel mean m, projected standard deviation sigma = sigma_hat * f / z, and their k-derivatives.
struct ProjectedGaussian {
  Eigen::Vector2d mean;
  Eigen::Vector2d dmean_dk;
  double sigma = 0.0;
  double dsigma_dk = 0.0;
};

// 1 for the printed form's exponent -|d|^2/S, 2 for the exact -|d|^2/(2S).
inline double ExponentDivisor(OverlapForm form) {
  return form == OverlapForm::kPrinted ? 1.0 : 2.0;
}

// The weight of sigma_i^2 in S.
inline double ImageVarianceFactor(OverlapForm form) {
  return form == OverlapForm::kPatch ? 1.0 / 3.0 : 1.0;
}

// The overlap E of a projected surface Gaussian with an image Gaussian (mean `image_mean`, standard
// deviation `image_sigma`). When `dE_dk` is not null it receives dE/dk.
inline double GaussianOverlap(OverlapForm form, const ProjectedGaussian& surface,
                              const Eigen::Vector2d& image_mean, double image_sigma,
                              double* dE_dk = nullptr) {
  const double var_s = surface.sigma * surface.sigma;
  const double var_i = image_sigma * image_sigma;
  const double sum = var_s + ImageVarianceFactor(form) * var_i;
  const Eigen::Vector2d d = image_mean - surface.mean;
  const double c = ExponentDivisor(form);
  const double d2 = d.squaredNorm();
  const double overlap = 2.0 * M_PI * var_s * var_i / sum * std::exp(-d2 / (c * sum));
  if (dE_dk != nullptr) {
    // d ln E / d var_s = 1/var_s - 1/S + |d|^2/(c S^2);  d ln E / d m_s = 2 d / (c S).
    const double dlog_dvar = 1.0 / var_s - 1.0 / sum + d2 / (c * sum * sum);
    const double dvar_dk = 2.0 * surface.sigma * surface.dsigma_dk;
    const double dlog_dmean = 2.0 * d.dot(surface.dmean_dk) / (c * sum);
    *dE_dk = overlap * (dlog_dvar * dvar_dk + dlog_dmean);
  }
  return overlap;
}

// The overlap of an image Gaussian with itself, pi sigma^2 (the same in both forms).
inline double SelfOverlap(double sigma) { return M_PI * sigma * sigma; }

// The Wendland function of the paper: (1 - d/D)^4 (4 d/D + 1) for d < D, else 0. Smooth (C^2) at
// the cut-off, 1 at d = 0.
inline double Wendland(double distance, double cutoff) {
  if (distance >= cutoff) return 0.0;
  const double x = distance / cutoff;
  const double one_minus = 1.0 - x;
  return one_minus * one_minus * one_minus * one_minus * (4.0 * x + 1.0);
}

}  // namespace finecap

#endif  // FINECAP_GAUSSIAN_OVERLAP_H_
