// Helpers shared by the camera file readers and writers (not part of the public API): OpenCV's
// distortion coefficients and rotations, and the checks every camera format applies.
#ifndef FINECAP_SRC_CAMERA_IO_UTIL_H_
#define FINECAP_SRC_CAMERA_IO_UTIL_H_

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "finecap/geometry/camera.h"

namespace finecap {
namespace internal {

// Camera::Validate, except that a size of 0 x 0 (not yet known) is accepted.
void ValidateCameraExceptUnknownSize(const Camera& camera, const std::string& where);

// OpenCV's distortion coefficients as a file lists them, in finecap's 12 (the rest zero): 0, 4,
// 5, 8 or 12 coefficients, or 14 with the tilted-sensor pair (tauX, tauY) zero. Throws
// Error(where, ...) for any other count or a non-zero tilt, which finecap's model lacks.
std::array<double, 12> OpenCvDistortion(const std::vector<double>& coefficients,
                                        const std::string& where);

// The fewest coefficients that hold `distortion` as OpenCV counts them: 5, 8 or 12.
std::vector<double> ShortestOpenCvDistortion(const std::array<double, 12>& distortion);

// The rotation of a Rodrigues vector (OpenCV's rvec): its direction the axis, its length the
// angle. A non-finite vector gives a non-finite matrix, which the camera's validation names.
Eigen::Matrix3d RotationOfRodrigues(const Eigen::Vector3d& vector);

// Makes each camera's R exactly orthonormal (NearestRotation) when it is a rotation up to the
// rounding of a file, and prints one warning naming `where` when any was further than 1e-6 from
// orthonormal (what Camera::Validate allows). Throws Error naming `where` and the camera for an R
// that is not a rotation at all. A matrix orthonormal to 1e-9 is left as it is, so that the
// writers' 17 digits read back to the same bits.
void MakeRotationsExact(std::vector<Camera>* cameras, const std::string& where);

// Throws Error(where, ...) when two cameras share a name.
void RequireUniqueCameraNames(const std::vector<Camera>& cameras, const std::string& where);

}  // namespace internal
}  // namespace finecap

#endif  // FINECAP_SRC_CAMERA_IO_UTIL_H_
