// Small helpers shared by the file readers (not part of the public API).
#ifndef FINECAP_SRC_IO_UTIL_H_
#define FINECAP_SRC_IO_UTIL_H_

#include <array>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "finecap/camera.h"

namespace finecap {
namespace internal {

// Throws Error(path, ...) unless `path` is an existing regular file.
void RequireFile(const std::string& path);

// The whole file as bytes. Throws Error naming the file when it is missing or unreadable.
std::string ReadWholeFile(const std::string& path);

// Parses the whole of `token` as a number; false when it is not one (or has trailing characters).
bool ParseDouble(const std::string& token, double* value);
bool ParseInt(const std::string& token, int* value);

// "a, b, c": names listed in an error message.
std::string JoinWithCommas(const std::vector<std::string>& names);

// Whitespace-separated tokens of `line`.
std::vector<std::string> SplitWhitespace(const std::string& line);

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

// `text` as a JSON string literal: quoted, with quotes, backslashes and control characters
// escaped.
std::string JsonString(const std::string& text);

// `value` as a JSON number with 10 significant digits; "null" when it is not finite (JSON has no
// NaN or infinity).
std::string JsonNumber(double value);

// Encodes `image` (8- or 16-bit, 1, 3 or 4 channels) as PNG and writes it to `path` atomically.
// Throws Error naming the file when it cannot be encoded or written.
void WritePng(const std::string& path, const cv::Mat& image);

}  // namespace internal
}  // namespace finecap

#endif  // FINECAP_SRC_IO_UTIL_H_
