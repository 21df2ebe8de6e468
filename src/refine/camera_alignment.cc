#include "refine/camera_alignment.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "finecap/geometry/bilinear.h"

namespace finecap {
namespace {

// Samples that a camera must share with the others for its step to count.
constexpr int kMinSharedSamples = 50;

// Whether camera `camera` reads sample j: it sees it and, with a mask, on its foreground.
bool Reads(const CameraInput& camera, int j) {
  return camera.samples_visible[j] != 0 &&
         (camera.samples_on_foreground.empty() || camera.samples_on_foreground[j] != 0);
}

// Whether a read at `pixel` stays inside the image with its four pixels.
bool Inside(const cv::Mat& image, const Eigen::Vector2d& pixel) {
  return pixel.x() >= 0.0 && pixel.y() >= 0.0 && pixel.x() < image.cols - 1.0 &&
         pixel.y() < image.rows - 1.0;
}

// At most kMaxAlignmentSamples of `num_samples` samples, every stride-th: spread over the
// surface as its numbering is (the vertices, then each edge's points, then each face's).
std::vector<int> SpreadSamples(int num_samples) {
  const int stride = std::max(1, (num_samples + kMaxAlignmentSamples - 1) / kMaxAlignmentSamples);
  std::vector<int> chosen;
  for (int j = 0; j < num_samples; j += stride) chosen.push_back(j);
  return chosen;
}

// One round's reads of the samples `chosen`: each camera's colours (3 x chosen, NaN where it does
// not read the sample) and the pixels it read them at, and per sample their sum over the cameras
// and how many read it, from which each camera's "others' mean" follows without summing the
// others again.
struct RoundReads {
  std::vector<Eigen::Matrix3Xf> colors;
  std::vector<Eigen::Matrix2Xd> pixels;
  Eigen::Matrix3Xd sums;
  std::vector<int> counts;
};

// Each camera's pixels of the samples `chosen` as its calibration gives them (NaN where it does
// not read the sample). A shift of the principal point shifts every pixel by as much, so that the
// rounds project the samples once.
std::vector<Eigen::Matrix2Xd> ProjectChosen(const Eigen::Matrix3Xd& points,
                                            const std::vector<int>& chosen,
                                            const std::vector<CameraInput>& cameras) {
  const int n = static_cast<int>(chosen.size());
  std::vector<Eigen::Matrix2Xd> pixels(cameras.size());
  for (size_t c = 0; c < cameras.size(); ++c) {
    const CameraInput& camera = cameras[c];
    pixels[c].setConstant(2, n, std::nan(""));
#pragma omp parallel for schedule(static)
    for (int i = 0; i < n; ++i) {
      if (Reads(camera, chosen[i])) pixels[c].col(i) = camera.camera.Project(points.col(chosen[i]));
    }
  }
  return pixels;
}

// The reads of one round, each camera's `projected` pixels moved by its `shifts`.
RoundReads ReadColors(const std::vector<Eigen::Matrix2Xd>& projected,
                      const std::vector<Eigen::Vector2d>& shifts,
                      const std::vector<CameraInput>& cameras) {
  const int n = static_cast<int>(projected.front().cols());
  RoundReads reads;
  std::vector<Eigen::Matrix3Xf>& colors = reads.colors;
  colors.resize(cameras.size());
  reads.pixels.resize(cameras.size());
  for (size_t c = 0; c < cameras.size(); ++c) {
    const CameraInput& camera = cameras[c];
    colors[c].setConstant(3, n, std::nanf(""));
    reads.pixels[c].resize(2, n);
#pragma omp parallel for schedule(static)
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector2d pixel = projected[c].col(i) + shifts[c];
      // NaN where the camera does not read the sample: not inside.
      if (!Inside(camera.pixels, pixel)) continue;
      double color[3];
      ReadBilinear(camera.pixels, pixel.x(), pixel.y(), 0.0, 0.0, color, nullptr);
      colors[c].col(i) = Eigen::Vector3d(color[0], color[1], color[2]).cast<float>();
      reads.pixels[c].col(i) = pixel;
    }
  }
  reads.sums.setZero(3, n);
  reads.counts.assign(n, 0);
  for (const Eigen::Matrix3Xf& camera_colors : colors) {
    for (int i = 0; i < n; ++i) {
      if (!std::isfinite(camera_colors(0, i))) continue;
      reads.sums.col(i) += camera_colors.col(i).cast<double>();
      ++reads.counts[i];
    }
  }
  return reads;
}

// Camera c's least-squares step (pixels) towards the mean of the other cameras' colours, or
// zero when it shares too few samples with them or their gradients leave the step undetermined.
Eigen::Vector2d StepOf(int c, const std::vector<CameraInput>& cameras, const RoundReads& reads) {
  const cv::Mat& image = cameras[c].pixels;
  const Eigen::Matrix3Xf& own = reads.colors[c];
  Eigen::Matrix2d normal = Eigen::Matrix2d::Zero();
  Eigen::Vector2d right = Eigen::Vector2d::Zero();
  int shared = 0;
  for (Eigen::Index i = 0; i < own.cols(); ++i) {
    const int num_others = reads.counts[i] - 1;
    if (!std::isfinite(own(0, i)) || num_others == 0) continue;
    ++shared;
    const Eigen::Vector2d pixel = reads.pixels[c].col(i);
    double along_x[3], along_y[3];
    ReadCellGradient(CellAt(image, pixel.x(), pixel.y(), 1.0, 1.0), RowStep(image), along_x,
                     along_y);
    const Eigen::Vector3d colour = own.col(i).cast<double>();
    const Eigen::Vector3d difference = colour - (reads.sums.col(i) - colour) / num_others;
    for (int channel = 0; channel < 3; ++channel) {
      const Eigen::Vector2d gradient(along_x[channel], along_y[channel]);
      normal += gradient * gradient.transpose();
      right -= gradient * difference[channel];
    }
  }
  // A direction without gradient (a plain or striped region alone) leaves the step undetermined.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(normal);
  if (shared < kMinSharedSamples || !(eigen.eigenvalues()[0] > 1e-9 * eigen.eigenvalues()[1])) {
    return Eigen::Vector2d::Zero();
  }
  return normal.ldlt().solve(right);
}

}  // namespace

std::vector<Eigen::Vector2d> AlignCameras(const Eigen::Matrix3Xd& points, int max_rounds,
                                          std::vector<CameraInput>* cameras) {
  const int num_cameras = static_cast<int>(cameras->size());
  std::vector<Eigen::Vector2d> shifts(num_cameras, Eigen::Vector2d::Zero());
  const std::vector<int> chosen = SpreadSamples(static_cast<int>(points.cols()));
  if (chosen.empty() || num_cameras == 0) return shifts;
  const std::vector<Eigen::Matrix2Xd> projected = ProjectChosen(points, chosen, *cameras);
  for (int round = 0; round < max_rounds; ++round) {
    const RoundReads reads = ReadColors(projected, shifts, *cameras);
    std::vector<Eigen::Vector2d> steps(num_cameras);
#pragma omp parallel for schedule(dynamic, 1)
    for (int c = 0; c < num_cameras; ++c) {
      // Half the step: the others, which camera c was compared with, move too.
      steps[c] = 0.5 * StepOf(c, *cameras, reads);
      const double length = steps[c].norm();
      if (length > kMaxAlignmentStepPixels) steps[c] *= kMaxAlignmentStepPixels / length;
    }
    double largest = 0.0;
    for (int c = 0; c < num_cameras; ++c) {
      largest = std::max(largest, steps[c].norm());
      shifts[c] += steps[c];
    }
    if (largest < kAlignmentTolerancePixels) break;
  }
  // The rounds read at the pixels projected once, moved by the shifts: the calibrations change
  // only now.
  for (int c = 0; c < num_cameras; ++c) {
    (*cameras)[c].camera.K(0, 2) += shifts[c].x();
    (*cameras)[c].camera.K(1, 2) += shifts[c].y();
  }
  return shifts;
}

}  // namespace finecap
