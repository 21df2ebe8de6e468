// A calibrated pinhole camera with OpenCV's lens distortion.
//
// Convention, used in every file finecap reads or writes: world units are metres; a world point X
// maps to camera coordinates x_cam = R * X + t; OpenCV axes (x right, y down, z forward); the pixel
// is K * distort(x_cam / z), with the centre of the top-left pixel at (0, 0); distortion follows
// OpenCV's model with up to 12 coefficients (k1, k2, p1, p2, k3, k4, k5, k6, s1, s2, s3, s4): the
// radial polynomial, the rational model's denominator (k4..k6) and thin prism (s1..s4), so that
// a calibration made with CALIB_RATIONAL_MODEL or CALIB_THIN_PRISM_MODEL is used as it is.
#ifndef FINECAP_GEOMETRY_CAMERA_H_
#define FINECAP_GEOMETRY_CAMERA_H_

#include <array>
#include <string>

#include <Eigen/Core>

namespace finecap {

struct Camera {
  std::string name;
  int width = 0;  // Image size in pixels.
  int height = 0;
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();  // Intrinsics; K(0,1) is the skew.
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  // World-to-camera rotation.
  Eigen::Vector3d t = Eigen::Vector3d::Zero();      // World-to-camera translation, metres.
  // OpenCV's (k1, k2, p1, p2, k3, k4, k5, k6, s1, s2, s3, s4); a 4- or 5-coefficient
  // calibration leaves the rest zero. All zero once the images are undistorted on load.
  std::array<double, 12> distortion = {};

  double fx() const { return K(0, 0); }
  double fy() const { return K(1, 1); }
  // Mean focal length in pixels: scales a metric length at depth z to pixels (sigma_s = f*s/z).
  double focal() const { return 0.5 * (K(0, 0) + K(1, 1)); }

  bool HasDistortion() const;
  // A copy with the distortion set to zero: the camera of the undistorted images.
  Camera Undistorted() const;

  // Camera centre in world coordinates, -R^T t.
  Eigen::Vector3d Center() const { return -R.transpose() * t; }
  Eigen::Vector3d ToCamera(const Eigen::Vector3d& world) const { return R * world + t; }
  // The cosine of the angle between `normal` (unit) at world point `point` and the ray from it to
  // the camera centre: 1 head-on, 0 at grazing incidence, negative facing away.
  double ViewCosine(const Eigen::Vector3d& point, const Eigen::Vector3d& normal) const {
    return normal.dot((Center() - point).normalized());
  }
  // Depth of a world point along the optical axis.
  double Depth(const Eigen::Vector3d& world) const { return R.row(2).dot(world) + t(2); }

  // Pixel of a world point, lens distortion included. When `jacobian` is given it receives
  // d(pixel)/d(world point). The point must be in front of the camera (Depth > 0).
  Eigen::Vector2d Project(const Eigen::Vector3d& world,
                          Eigen::Matrix<double, 2, 3>* jacobian = nullptr) const;

  // Throws Error(where, ...) unless the camera is usable: positive size and focal lengths, K
  // upper triangular with K(2,2) = 1, R a proper rotation (orthonormal, determinant +1, to 1e-6:
  // readers of rounded files make it exact first with NearestRotation), finite values
  // everywhere. A skew K(0,1), however small or large, is part of the model: Project and the
  // undistortion on load both use it.
  void Validate(const std::string& where) const;
};

// How far from orthonormal a rotation read from a file may be, as ||R^T R - I|| (Frobenius).
// Rounding each entry by d moves it by at most about 6 d: 1e-3 accepts entries rounded to 4
// decimals (d = 5e-5) and anything finer, single precision included (d = 6e-8), while a scale of
// 1.001, a shear or a reflection is refused. The nearest rotation differs from such an R by at
// most about half the tolerance (Frobenius norm), which moves a ray by under 5e-4 radians: less
// than 0.5 px at a focal length of 1000 px, and far less for the rounding it is meant for.
constexpr double kRotationTolerance = 1e-3;

// The rotation nearest to `matrix` in the Frobenius norm (its polar decomposition, by SVD), for a
// matrix that is a rotation up to rounding: ||R^T R - I|| < kRotationTolerance and determinant
// > 0. `deviation`, when given, receives ||R^T R - I||. Throws Error(where, ...) for anything
// else (scaled, sheared, singular, reflecting or non-finite), which is not a rotation at all.
Eigen::Matrix3d NearestRotation(const Eigen::Matrix3d& matrix, const std::string& where,
                                double* deviation = nullptr);

}  // namespace finecap

#endif  // FINECAP_GEOMETRY_CAMERA_H_
