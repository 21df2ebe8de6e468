#include "energy/pixel_consensus_similarity.h"

#include <algorithm>
#include <cmath>

#include <opencv2/core.hpp>

#include "finecap/util/error.h"
#include "model/surface_projection.h"

namespace finecap {
namespace {

// A patch needs its own sample and at least this many more to have a shape worth comparing.
constexpr int kMinPatchSamples = 4;

// The bilinear interpolant of a CV_32FC3 image at (x, y), pixel centres at integers, and its
// derivatives along x and y (those of the interpolant, so that they are exact for the function
// the solvers see). Outside the image the position is clamped to its border, where the
// derivative across the border is zero.
struct BilinearRead {
  Eigen::Vector3d color, dx, dy;
};

BilinearRead ReadBilinear(const cv::Mat& image, double x, double y) {
  const double max_x = image.cols - 1.0, max_y = image.rows - 1.0;
  const bool inside_x = x > 0.0 && x<max_x, inside_y = y> 0.0 && y < max_y;
  x = std::clamp(x, 0.0, max_x);
  y = std::clamp(y, 0.0, max_y);
  const int x0 = std::min(static_cast<int>(x), image.cols - 2);
  const int y0 = std::min(static_cast<int>(y), image.rows - 2);
  const double u = x - x0, v = y - y0;
  const cv::Vec3f* row0 = image.ptr<cv::Vec3f>(y0);
  const cv::Vec3f* row1 = image.ptr<cv::Vec3f>(y0 + 1);
  BilinearRead read;
  for (int channel = 0; channel < 3; ++channel) {
    const double c00 = row0[x0][channel], c10 = row0[x0 + 1][channel];
    const double c01 = row1[x0][channel], c11 = row1[x0 + 1][channel];
    const double top = c00 + u * (c10 - c00), bottom = c01 + u * (c11 - c01);
    read.color[channel] = top + v * (bottom - top);
    read.dx[channel] = inside_x ? (1.0 - v) * (c10 - c00) + v * (c11 - c01) : 0.0;
    read.dy[channel] = inside_y ? bottom - top : 0.0;
  }
  return read;
}

}  // namespace

PixelConsensusSimilarity::PixelConsensusSimilarity(const SurfaceSamples& samples,
                                                   const std::vector<CameraInput>& cameras,
                                                   const ConsensusOptions& options)
    : PatchAgreementTerm(options, static_cast<int>(cameras.size())),
      samples_(samples),
      cameras_(cameras) {
  for (const CameraInput& camera : cameras) {
    Require(camera.pixels.type() == CV_32FC3 && camera.pixels.cols >= 2 && camera.pixels.rows >= 2,
            camera.camera.name, "the samples need the camera's image, converted (CV_32FC3)");
    Require(camera.samples_visible.size() == static_cast<size_t>(samples.size()),
            camera.camera.name, "visibility must have one flag per surface sample");
  }
  for (int s = 0; s < static_cast<int>(samples.patches.size()); ++s) {
    const std::vector<int>& patch = samples.patches[s];
    if (static_cast<int>(patch.size()) < kMinPatchSamples) continue;
    std::vector<int> seen_by;
    for (size_t c = 0; c < cameras.size(); ++c) {
      const auto unseen = [&](int j) { return cameras[c].samples_visible[j] == 0; };
      if (std::none_of(patch.begin(), patch.end(), unseen)) seen_by.push_back(static_cast<int>(c));
    }
    if (static_cast<int>(seen_by.size()) >= options_.min_cameras) AddPatch(s, patch, seen_by);
  }
  shape_ = Eigen::VectorXd::Zero(samples.size());
  parameter_shape_ = Eigen::VectorXd::Zero(samples.patches.size());
  WeighPatches();
}

Eigen::Vector3d PixelConsensusSimilarity::SampleColor(int c, int j, double k,
                                                      Eigen::Vector3d* derivative) const {
  const CameraInput& camera = cameras_[c];
  const ProjectedGaussian projected = ProjectSurfaceGaussian(
      camera.camera, samples_.base.col(j), samples_.normals.col(j), k, /*sigma_hat=*/0.0);
  const BilinearRead read = ReadBilinear(camera.pixels, projected.mean.x(), projected.mean.y());
  if (derivative != nullptr) {
    *derivative = read.dx * projected.dmean_dk.x() + read.dy * projected.dmean_dk.y();
  }
  return read.color;
}

void PixelConsensusSimilarity::PatchColors(int b, double k, double* colors,
                                           double* derivatives) const {
  const int n = PatchSize(b), num_cameras = NumCameras(b);
  const int* members = Members(b);
  const double centre_shape = parameter_shape_[blocks_[b].parameters[0]];
  for (int a = 0; a < num_cameras; ++a) {
    const int c = Cameras(b)[a];
    for (int m = 0; m < n; ++m) {
      const int i = a * n + m;
      Eigen::Vector3d derivative;
      const Eigen::Vector3d color =
          SampleColor(c, members[m], k + shape_[members[m]] - centre_shape,
                      derivatives != nullptr ? &derivative : nullptr);
      Eigen::Map<Eigen::Vector3d>(colors + 3 * i) = color;
      if (derivatives != nullptr) Eigen::Map<Eigen::Vector3d>(derivatives + 3 * i) = derivative;
    }
  }
}

void PixelConsensusSimilarity::SetPatchShape(const Eigen::VectorXd& shape) {
  Require(shape.size() == static_cast<Eigen::Index>(samples_.patches.size()),
          "pixel consensus similarity", "one patch shape entry per surface Gaussian expected");
  parameter_shape_ = shape;
  shape_ = samples_.weights * shape;
}

}  // namespace finecap
