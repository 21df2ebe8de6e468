#include "energy/terms/paper/paper_similarity.h"

#include <cmath>

#include "model/surface_projection.h"

namespace finecap {

PaperSimilarity::PaperSimilarity(const SurfaceGaussians& surface,
                                 const std::vector<EnergyView>& views, OverlapForm form)
    : surface_(surface), views_(views), form_(form) {
  // One residual block per image Gaussian that any pair reaches, listing its pairs.
  for (int c = 0; c < static_cast<int>(views_.size()); ++c) {
    const CameraPairs& pairs = views_[c].pairs;
    std::vector<std::vector<int>> pairs_of_image(views_[c].image->size());
    for (int p = 0; p < pairs.num_pairs(); ++p) pairs_of_image[pairs.image_ids[p]].push_back(p);
    std::vector<int> surface_of_pair(pairs.num_pairs());
    for (size_t j = 0; j < pairs.surface_ids.size(); ++j) {
      for (int p = pairs.begin[j]; p < pairs.begin[j + 1]; ++p) {
        surface_of_pair[p] = pairs.surface_ids[j];
      }
    }
    for (int i = 0; i < static_cast<int>(pairs_of_image.size()); ++i) {
      if (pairs_of_image[i].empty()) continue;
      ResidualBlock block;
      block.num_residuals = 1;
      block_camera_.push_back(c);
      block_image_.push_back(i);
      block_pair_begin_.push_back(static_cast<int>(block_pairs_.size()));
      for (int p : pairs_of_image[i]) {
        block.parameters.push_back(surface_of_pair[p]);
        block_pairs_.push_back(p);
      }
      blocks_.push_back(std::move(block));
    }
  }
  block_pair_begin_.push_back(static_cast<int>(block_pairs_.size()));
}

void PaperSimilarity::ComputeOverlaps(int camera, const Eigen::VectorXd& k, bool with_derivatives,
                                      CameraOverlaps* overlaps) const {
  const EnergyView& view = views_[camera];
  const CameraPairs& pairs = view.pairs;
  overlaps->overlap.resize(pairs.num_pairs());
  overlaps->derivative.resize(with_derivatives ? pairs.num_pairs() : 0);
  overlaps->sums.assign(view.image->size(), 0.0);
  for (size_t j = 0; j < pairs.surface_ids.size(); ++j) {
    const int s = pairs.surface_ids[j];
    const ProjectedGaussian projected = ProjectSurfaceGaussian(
        view.camera, surface_.base.col(s), surface_.normals.col(s), k[s], surface_.sigma_hat);
    for (int p = pairs.begin[j]; p < pairs.begin[j + 1]; ++p) {
      const ImageGaussian& g = (*view.image)[pairs.image_ids[p]];
      double derivative = 0.0;
      const double overlap = GaussianOverlap(form_, projected, Eigen::Vector2d(g.x, g.y), g.sigma,
                                             with_derivatives ? &derivative : nullptr);
      const double weight = pairs.color_weight(p);
      overlaps->overlap[p] = weight * overlap;
      if (with_derivatives) overlaps->derivative[p] = weight * derivative;
      overlaps->sums[pairs.image_ids[p]] += overlaps->overlap[p];
    }
  }
}

double PaperSimilarity::Evaluate(const Eigen::VectorXd& k, Eigen::VectorXd* gradient) const {
  const int num_cameras = static_cast<int>(views_.size());
  std::vector<double> camera_similarity(num_cameras, 0.0);
  std::vector<Eigen::VectorXd> camera_gradient(num_cameras);
#pragma omp parallel for schedule(dynamic, 1)
  for (int c = 0; c < num_cameras; ++c) {
    CameraOverlaps overlaps;
    ComputeOverlaps(c, k, gradient != nullptr, &overlaps);
    const ImageGaussians& image = *views_[c].image;
    for (int i = 0; i < image.size(); ++i) {
      const double self = SelfOverlap(image[i].sigma);
      camera_similarity[c] += std::min(overlaps.sums[i], self) / self;
    }
    if (gradient == nullptr) continue;
    // Only image Gaussians whose min() is not clamped pass a derivative on.
    const CameraPairs& pairs = views_[c].pairs;
    camera_gradient[c] = Eigen::VectorXd::Zero(k.size());
    for (size_t j = 0; j < pairs.surface_ids.size(); ++j) {
      double sum = 0.0;
      for (int p = pairs.begin[j]; p < pairs.begin[j + 1]; ++p) {
        const int i = pairs.image_ids[p];
        const double self = SelfOverlap(image[i].sigma);
        if (overlaps.sums[i] < self) sum += overlaps.derivative[p] / self;
      }
      camera_gradient[c][pairs.surface_ids[j]] += sum;
    }
  }
  double similarity = 0.0;
  for (double value : camera_similarity) similarity += value;
  if (gradient != nullptr) {
    *gradient = Eigen::VectorXd::Zero(k.size());
    for (const Eigen::VectorXd& g : camera_gradient) *gradient += g;
    *gradient /= num_cameras;
  }
  return similarity / num_cameras;
}

void PaperSimilarity::PrepareResiduals(const Eigen::VectorXd& k, bool with_jacobians) {
  const int num_cameras = static_cast<int>(views_.size());
  std::vector<CameraOverlaps> overlaps(num_cameras);
#pragma omp parallel for schedule(dynamic, 1)
  for (int c = 0; c < num_cameras; ++c) ComputeOverlaps(c, k, with_jacobians, &overlaps[c]);

  const double scale = 1.0 / std::sqrt(static_cast<double>(num_cameras));
  const int num_blocks = static_cast<int>(blocks_.size());
  residuals_.resize(num_blocks);
  jacobians_.resize(with_jacobians ? block_pairs_.size() : 0);
#pragma omp parallel for schedule(static)
  for (int b = 0; b < num_blocks; ++b) {
    const CameraOverlaps& camera = overlaps[block_camera_[b]];
    const double self = SelfOverlap((*views_[block_camera_[b]].image)[block_image_[b]].sigma);
    const double explained = camera.sums[block_image_[b]] / self;
    residuals_[b] = scale * (1.0 - std::min(explained, 1.0));
    if (!with_jacobians) continue;
    for (int q = block_pair_begin_[b]; q < block_pair_begin_[b + 1]; ++q) {
      jacobians_[q] = explained < 1.0 ? -scale * camera.derivative[block_pairs_[q]] / self : 0.0;
    }
  }
}

void PaperSimilarity::BlockResiduals(int block, double* residuals, double* jacobian) const {
  residuals[0] = residuals_[block];
  if (jacobian == nullptr) return;
  const int begin = block_pair_begin_[block];
  for (int q = begin; q < block_pair_begin_[block + 1]; ++q) jacobian[q - begin] = jacobians_[q];
}

}  // namespace finecap
