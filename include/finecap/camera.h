// A calibrated pinhole camera with OpenCV's lens distortion.
//
// Convention, used in every file finecap reads or writes: world units are metres; a world point X
// maps to camera coordinates x_cam = R * X + t; OpenCV axes (x right, y down, z forward); the pixel
// is K * distort(x_cam / z), with the centre of the top-left pixel at (0, 0); distortion follows
// OpenCV's model with coefficients (k1, k2, p1, p2, k3).
#ifndef FINECAP_CAMERA_H_
#define FINECAP_CAMERA_H_

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
  // OpenCV's (k1, k2, p1, p2, k3). All zero once the images are undistorted on load.
  std::array<double, 5> distortion = {0, 0, 0, 0, 0};

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
  // Depth of a world point along the optical axis.
  double Depth(const Eigen::Vector3d& world) const { return R.row(2).dot(world) + t(2); }

  // Pixel of a world point, lens distortion included. When `jacobian` is given it receives
  // d(pixel)/d(world point). The point must be in front of the camera (Depth > 0).
  Eigen::Vector2d Project(const Eigen::Vector3d& world,
                          Eigen::Matrix<double, 2, 3>* jacobian = nullptr) const;

  // Throws Error(where, ...) unless the camera is usable: positive size and focal lengths, R a
  // proper rotation (orthonormal, determinant +1, to 1e-6), finite values everywhere.
  void Validate(const std::string& where) const;
};

}  // namespace finecap

#endif  // FINECAP_CAMERA_H_
