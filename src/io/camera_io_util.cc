#include "io/camera_io_util.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <set>
#include <sstream>

#include <Eigen/Geometry>

#include "finecap/util/error.h"

namespace finecap {
namespace internal {

void ValidateCameraExceptUnknownSize(const Camera& camera, const std::string& where) {
  if (camera.width != 0 || camera.height != 0) {
    camera.Validate(where);
    return;
  }
  Camera sized = camera;
  sized.width = sized.height = 1;  // Only the size check is skipped.
  sized.Validate(where);
}

std::array<double, 12> OpenCvDistortion(const std::vector<double>& coefficients,
                                        const std::string& where) {
  const size_t count = coefficients.size();
  Require(count == 0 || count == 4 || count == 5 || count == 8 || count == 12 || count == 14, where,
          "OpenCV's distortion has 4, 5, 8, 12 or 14 coefficients (k1 k2 p1 p2 [k3 [k4 k5 k6 "
          "[s1 s2 s3 s4 [tauX tauY]]]]), not " +
              std::to_string(count));
  Require(count < 14 || (coefficients[12] == 0.0 && coefficients[13] == 0.0), where,
          "the tilted-sensor coefficients tauX, tauY (13th and 14th) must be zero: finecap's "
          "camera model has no tilted sensor");
  std::array<double, 12> distortion = {};
  std::copy(coefficients.begin(), coefficients.begin() + std::min<size_t>(count, 12),
            distortion.begin());
  return distortion;
}

std::vector<double> ShortestOpenCvDistortion(const std::array<double, 12>& distortion) {
  size_t used = 5;
  for (size_t i = 5; i < distortion.size(); ++i) {
    if (distortion[i] != 0.0) used = i < 8 ? std::max<size_t>(used, 8) : 12;
  }
  return std::vector<double>(distortion.begin(), distortion.begin() + used);
}

Eigen::Matrix3d RotationOfRodrigues(const Eigen::Vector3d& vector) {
  const double angle = vector.norm();
  if (!std::isfinite(angle)) return Eigen::Matrix3d::Constant(std::nan(""));
  if (angle < 1e-300) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, vector / angle).toRotationMatrix();
}

void MakeRotationsExact(std::vector<Camera>* cameras, const std::string& where) {
  constexpr double kLeftAsItIs = 1e-9;
  constexpr double kValidateTolerance = 1e-6;
  int projected = 0;
  double worst = 0.0;
  std::string worst_camera;
  for (Camera& camera : *cameras) {
    double deviation = 0.0;
    const Eigen::Matrix3d nearest =
        NearestRotation(camera.R, where + " (camera '" + camera.name + "')", &deviation);
    if (deviation > kLeftAsItIs) camera.R = nearest;
    if (deviation > kValidateTolerance) ++projected;
    if (deviation > worst) worst = deviation, worst_camera = camera.name;
  }
  if (projected == 0) return;
  std::ostringstream message;
  message << "finecap: warning: " << where << ": the rotation of " << projected << " camera"
          << (projected > 1 ? "s" : "") << " is orthonormal only up to rounding (worst: camera '"
          << worst_camera << "', ||R^T R - I|| = " << std::setprecision(2) << worst
          << "); using the nearest rotation\n";
  std::cerr << message.str();
}

void RequireUniqueCameraNames(const std::vector<Camera>& cameras, const std::string& where) {
  std::set<std::string> names;
  for (const Camera& camera : cameras) {
    Require(names.insert(camera.name).second, where,
            "camera name '" + camera.name + "' appears twice");
  }
}

}  // namespace internal
}  // namespace finecap
