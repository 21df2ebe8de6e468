// Projection of a surface Gaussian that slides along its normal, mu(k) = base + k * normal, into a
// pinhole camera (the undistorted camera of the loaded images).
#ifndef FINECAP_SURFACE_PROJECTION_H_
#define FINECAP_SURFACE_PROJECTION_H_

#include <Eigen/Core>

#include "finecap/geometry/camera.h"
#include "finecap/model/gaussian_overlap.h"

namespace finecap {

// The pixel mean of mu(k), the projected standard deviation sigma_hat * f / z (the paper's
// equation; `sigma_hat` in metres) and their derivatives with respect to k (metres).
// The camera's distortion is ignored: images are undistorted when loaded.
inline ProjectedGaussian ProjectSurfaceGaussian(const Camera& camera, const Eigen::Vector3d& base,
                                                const Eigen::Vector3d& normal, double k,
                                                double sigma_hat) {
  const Eigen::Vector3d p = camera.R * (base + k * normal) + camera.t;
  const Eigen::Vector3d dp_dk = camera.R * normal;
  const double inv_z = 1.0 / p.z();
  const double x = p.x() * inv_z;
  const double y = p.y() * inv_z;
  const double dx_dk = (dp_dk.x() - x * dp_dk.z()) * inv_z;
  const double dy_dk = (dp_dk.y() - y * dp_dk.z()) * inv_z;
  const Eigen::Matrix3d& K = camera.K;
  ProjectedGaussian projected;
  projected.mean = Eigen::Vector2d(K(0, 0) * x + K(0, 1) * y + K(0, 2), K(1, 1) * y + K(1, 2));
  projected.dmean_dk = Eigen::Vector2d(K(0, 0) * dx_dk + K(0, 1) * dy_dk, K(1, 1) * dy_dk);
  projected.sigma = sigma_hat * camera.focal() * inv_z;
  projected.dsigma_dk = -projected.sigma * inv_z * dp_dk.z();
  return projected;
}

}  // namespace finecap

#endif  // FINECAP_SURFACE_PROJECTION_H_
