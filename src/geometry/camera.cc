#include "finecap/geometry/camera.h"

#include <cmath>

#include <Eigen/LU>
#include <Eigen/SVD>

#include "finecap/util/error.h"

namespace finecap {

bool Camera::HasDistortion() const {
  for (double coefficient : distortion) {
    if (coefficient != 0.0) return true;
  }
  return false;
}

Camera Camera::Undistorted() const {
  Camera camera = *this;
  camera.distortion.fill(0.0);
  return camera;
}

Eigen::Vector2d Camera::Project(const Eigen::Vector3d& world,
                                Eigen::Matrix<double, 2, 3>* jacobian) const {
  const Eigen::Vector3d p = ToCamera(world);
  const double inv_z = 1.0 / p.z();
  const double x = p.x() * inv_z;
  const double y = p.y() * inv_z;
  const auto [k1, k2, p1, p2, k3, k4, k5, k6, s1, s2, s3, s4] = distortion;

  // OpenCV's model: a rational radial factor, tangential terms and thin prism terms.
  const double r2 = x * x + y * y;
  const double numerator = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
  const double denominator = 1.0 + r2 * (k4 + r2 * (k5 + r2 * k6));
  const double radial = numerator / denominator;
  const double prism_x = r2 * (s1 + r2 * s2);
  const double prism_y = r2 * (s3 + r2 * s4);
  const double xd = x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x) + prism_x;
  const double yd = y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y + prism_y;
  const Eigen::Vector2d pixel(K(0, 0) * xd + K(0, 1) * yd + K(0, 2), K(1, 1) * yd + K(1, 2));
  if (jacobian == nullptr) return pixel;

  // Chain rule: pixel <- distorted <- normalised <- camera point <- world point.
  const double dnumerator_dr2 = k1 + r2 * (2.0 * k2 + 3.0 * r2 * k3);
  const double ddenominator_dr2 = k4 + r2 * (2.0 * k5 + 3.0 * r2 * k6);
  const double dradial_dr2 = (dnumerator_dr2 - radial * ddenominator_dr2) / denominator;
  const double dprism_x_dr2 = s1 + 2.0 * r2 * s2;
  const double dprism_y_dr2 = s3 + 2.0 * r2 * s4;
  Eigen::Matrix2d d_distorted_d_normalised;
  d_distorted_d_normalised(0, 0) =
      radial + 2.0 * x * (x * dradial_dr2 + dprism_x_dr2) + 2.0 * p1 * y + 6.0 * p2 * x;
  d_distorted_d_normalised(0, 1) =
      2.0 * y * (x * dradial_dr2 + dprism_x_dr2) + 2.0 * p1 * x + 2.0 * p2 * y;
  d_distorted_d_normalised(1, 0) =
      2.0 * x * (y * dradial_dr2 + dprism_y_dr2) + 2.0 * p1 * x + 2.0 * p2 * y;
  d_distorted_d_normalised(1, 1) =
      radial + 2.0 * y * (y * dradial_dr2 + dprism_y_dr2) + 6.0 * p1 * y + 2.0 * p2 * x;
  Eigen::Matrix<double, 2, 3> d_normalised_d_camera;
  d_normalised_d_camera << inv_z, 0.0, -x * inv_z, 0.0, inv_z, -y * inv_z;
  Eigen::Matrix2d d_pixel_d_distorted;
  d_pixel_d_distorted << K(0, 0), K(0, 1), 0.0, K(1, 1);
  *jacobian = d_pixel_d_distorted * d_distorted_d_normalised * d_normalised_d_camera * R;
  return pixel;
}

Eigen::Matrix3d NearestRotation(const Eigen::Matrix3d& matrix, const std::string& where,
                                double* deviation) {
  Require(matrix.allFinite(), where, "non-finite value in R");
  const double distance = (matrix.transpose() * matrix - Eigen::Matrix3d::Identity()).norm();
  Require(distance < kRotationTolerance && matrix.determinant() > 0.0, where,
          "R is not a rotation matrix (singular, scaled, sheared or reflecting): ||R^T R - I|| = " +
              std::to_string(distance) + ", det R = " + std::to_string(matrix.determinant()) +
              "; a rounded rotation is accepted up to ||R^T R - I|| < " +
              std::to_string(kRotationTolerance));
  if (deviation != nullptr) *deviation = distance;
  // The orthogonal polar factor U V^T of R = U S V^T; det > 0 and S close to I make it proper.
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(matrix, Eigen::ComputeFullU | Eigen::ComputeFullV);
  return svd.matrixU() * svd.matrixV().transpose();
}

namespace {

// Length of the UTF-8 sequence that starts with `lead`, 0 when `lead` cannot start one.
int Utf8SequenceLength(unsigned char lead) {
  if (lead < 0x80) return 1;
  if (lead >= 0xc2 && lead <= 0xdf) return 2;
  if (lead >= 0xe0 && lead <= 0xef) return 3;
  if (lead >= 0xf0 && lead <= 0xf4) return 4;
  return 0;
}

// A camera's name names its image folder and is written back into YAML files: printable UTF-8
// (no control characters, which YAML escapes and a file system may refuse), no path separator.
bool IsUsableCameraName(const std::string& name) {
  if (name.empty() || name == "." || name == "..") return false;
  for (size_t i = 0; i < name.size();) {
    const unsigned char lead = static_cast<unsigned char>(name[i]);
    const int length = Utf8SequenceLength(lead);
    if (length == 0 || i + length > name.size()) return false;
    if (length == 1 && (lead < 0x20 || lead == 0x7f || lead == '/' || lead == '\\')) return false;
    for (int j = 1; j < length; ++j) {
      if ((static_cast<unsigned char>(name[i + j]) & 0xc0) != 0x80) return false;
    }
    // No overlong forms, surrogates or code points above U+10FFFF.
    const unsigned char second = length > 1 ? static_cast<unsigned char>(name[i + 1]) : 0x80;
    if ((lead == 0xe0 && second < 0xa0) || (lead == 0xed && second > 0x9f) ||
        (lead == 0xf0 && second < 0x90) || (lead == 0xf4 && second > 0x8f)) {
      return false;
    }
    i += length;
  }
  return true;
}

}  // namespace

void Camera::Validate(const std::string& where) const {
  const std::string at = where + " (camera '" + name + "')";
  Require(IsUsableCameraName(name), at,
          "a camera name must be printable UTF-8 text without '/' or '\\' (it names the "
          "camera's image folder)");
  Require(width > 0 && height > 0, at, "image size must be positive");
  Require(K.allFinite() && R.allFinite() && t.allFinite(), at, "non-finite value in K, R or t");
  for (double coefficient : distortion) {
    Require(std::isfinite(coefficient), at, "non-finite distortion coefficient");
  }
  Require(K(0, 0) > 0.0 && K(1, 1) > 0.0, at, "focal lengths must be positive");
  Require(K(1, 0) == 0.0 && K(2, 0) == 0.0 && K(2, 1) == 0.0 && K(2, 2) == 1.0, at,
          "K must be upper triangular with K(2,2) = 1");
  const double orthonormality = (R.transpose() * R - Eigen::Matrix3d::Identity()).norm();
  Require(orthonormality < 1e-6 && std::abs(R.determinant() - 1.0) < 1e-6, at,
          "R is not a rotation matrix (singular, scaled or reflecting)");
}

}  // namespace finecap
