#include "energy/pixel_consensus_similarity.h"

#include <algorithm>
#include <cmath>

#include "energy/patch_agreement.h"
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
    : samples_(samples),
      cameras_in_(cameras),
      options_(options),
      scale_(1.0 / std::sqrt(static_cast<double>(std::max<size_t>(cameras.size(), 1)))) {
  options_.Check();
  for (const CameraInput& camera : cameras) {
    Require(camera.pixels.type() == CV_32FC3 && camera.pixels.cols >= 2 && camera.pixels.rows >= 2,
            camera.camera.name, "the samples need the camera's image, converted (CV_32FC3)");
    Require(camera.samples_visible.size() == static_cast<size_t>(samples.size()),
            camera.camera.name, "visibility must have one flag per surface sample");
  }
  patch_begin_.push_back(0);
  camera_begin_.push_back(0);
  for (int s = 0; s < static_cast<int>(samples.patches.size()); ++s) {
    const std::vector<int>& patch = samples.patches[s];
    if (static_cast<int>(patch.size()) < kMinPatchSamples) continue;
    std::vector<int> seen_by;
    for (size_t c = 0; c < cameras.size(); ++c) {
      const auto unseen = [&](int j) { return cameras[c].samples_visible[j] == 0; };
      if (std::none_of(patch.begin(), patch.end(), unseen)) seen_by.push_back(static_cast<int>(c));
    }
    if (static_cast<int>(seen_by.size()) < options_.min_cameras) continue;
    members_.insert(members_.end(), patch.begin(), patch.end());
    patch_begin_.push_back(static_cast<int>(members_.size()));
    cameras_.insert(cameras_.end(), seen_by.begin(), seen_by.end());
    camera_begin_.push_back(static_cast<int>(cameras_.size()));
    blocks_.push_back({{s}, 3 * static_cast<int>(patch.size() * seen_by.size())});
  }
  residual_begin_.assign(1, 0);
  for (const ResidualBlock& block : blocks_) {
    residual_begin_.push_back(residual_begin_.back() + block.num_residuals);
  }
  shape_ = Eigen::VectorXd::Zero(samples.size());
  parameter_shape_ = Eigen::VectorXd::Zero(samples.patches.size());
  weights_.resize(blocks_.size());
#pragma omp parallel for schedule(dynamic, 64)
  for (int b = 0; b < static_cast<int>(blocks_.size()); ++b) {
    std::vector<double> colors(3 * PatchSize(b) * NumCameras(b));
    PatchColors(b, 0.0, colors.data(), nullptr);
    weights_[b] = internal::PatchContrast(PatchSize(b), NumCameras(b), colors.data());
  }
}

Eigen::Vector3d PixelConsensusSimilarity::SampleColor(int c, int j, double k,
                                                      Eigen::Vector3d* derivative) const {
  const CameraInput& camera = cameras_in_[c];
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
  const int* members = &members_[patch_begin_[b]];
  const double centre_shape = parameter_shape_[blocks_[b].parameters[0]];
  for (int a = 0; a < num_cameras; ++a) {
    const int c = cameras_[camera_begin_[b] + a];
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

void PixelConsensusSimilarity::PlainResiduals(int b, double k, double* residuals,
                                              double* jacobian) const {
  // The colours become the residuals in place.
  PatchColors(b, k, residuals, jacobian);
  internal::AgreementResiduals(PatchSize(b), NumCameras(b), options_.contrast_floor,
                               !options_.gain_per_channel, scale_ * weights_[b], residuals,
                               jacobian);
}

double PixelConsensusSimilarity::LossScale(int b) const {
  return internal::AgreementLossScale(PatchSize(b), NumCameras(b), scale_ * weights_[b],
                                      options_.robust_fraction);
}

SimilarityTerm::BlockSummary PixelConsensusSimilarity::SummaryAt(int b, double k,
                                                                 bool with_derivatives) const {
  thread_local std::vector<double> residuals, jacobian;
  const int num_residuals = blocks_[b].num_residuals;
  residuals.resize(num_residuals);
  jacobian.resize(with_derivatives ? num_residuals : 0);
  PlainResiduals(b, k, residuals.data(), with_derivatives ? jacobian.data() : nullptr);
  BlockSummary plain;
  if (with_derivatives) {
    plain = Summarise(residuals.data(), jacobian.data(), num_residuals);
  } else {
    for (int r = 0; r < num_residuals; ++r) plain.squared_norm += residuals[r] * residuals[r];
  }
  return internal::Robustify(LossScale(b), plain, with_derivatives);
}

double PixelConsensusSimilarity::Evaluate(const Eigen::VectorXd& k,
                                          Eigen::VectorXd* gradient) const {
  if (gradient != nullptr) *gradient = Eigen::VectorXd::Zero(k.size());
  const int num_blocks = static_cast<int>(blocks_.size());
  double sum_of_squares = 0.0;
#pragma omp parallel for schedule(dynamic, 64) reduction(+ : sum_of_squares)
  for (int b = 0; b < num_blocks; ++b) {
    const int s = blocks_[b].parameters[0];
    const BlockSummary summary = SummaryAt(b, k[s], gradient != nullptr);
    sum_of_squares += summary.squared_norm;
    // Each block owns one parameter: no two threads write the same entry.
    if (gradient != nullptr) (*gradient)[s] = -summary.gradient;
  }
  return -0.5 * sum_of_squares;
}

void PixelConsensusSimilarity::PrepareResiduals(const Eigen::VectorXd& k, bool with_jacobians) {
  residuals_.resize(residual_begin_.back());
  jacobians_.resize(with_jacobians ? residual_begin_.back() : 0);
  const int num_blocks = static_cast<int>(blocks_.size());
#pragma omp parallel for schedule(dynamic, 64)
  for (int b = 0; b < num_blocks; ++b) {
    double* residuals = &residuals_[residual_begin_[b]];
    double* jacobian = with_jacobians ? &jacobians_[residual_begin_[b]] : nullptr;
    PlainResiduals(b, k[blocks_[b].parameters[0]], residuals, jacobian);
    internal::Robustify(LossScale(b), blocks_[b].num_residuals, residuals, jacobian);
  }
}

void PixelConsensusSimilarity::BlockResiduals(int block, double* residuals,
                                              double* jacobian) const {
  const long begin = residual_begin_[block];
  const int num_residuals = blocks_[block].num_residuals;
  std::copy_n(&residuals_[begin], num_residuals, residuals);
  if (jacobian != nullptr) std::copy_n(&jacobians_[begin], num_residuals, jacobian);
}

void PixelConsensusSimilarity::PrepareBlockSummaries(const Eigen::VectorXd& k) {
  const int num_blocks = static_cast<int>(blocks_.size());
  summaries_.resize(num_blocks);
#pragma omp parallel for schedule(dynamic, 64)
  for (int b = 0; b < num_blocks; ++b) {
    summaries_[b] = SummaryAt(b, k[blocks_[b].parameters[0]], true);
  }
}

void PixelConsensusSimilarity::BlockCosts(const Eigen::VectorXd& k, std::vector<double>* costs) {
  const int num_blocks = static_cast<int>(blocks_.size());
  costs->resize(num_blocks);
#pragma omp parallel for schedule(dynamic, 64)
  for (int b = 0; b < num_blocks; ++b) {
    (*costs)[b] = SummaryAt(b, k[blocks_[b].parameters[0]], false).squared_norm;
  }
}

}  // namespace finecap
