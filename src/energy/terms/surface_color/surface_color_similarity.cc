#include "energy/terms/surface_color/surface_color_similarity.h"

#include <cmath>

#include "model/image_color.h"
#include "model/surface_projection.h"

namespace finecap {

using internal::ColorAccumulator;

SurfaceColorSimilarity::SurfaceColorSimilarity(const SurfaceGaussians& surface,
                                               const std::vector<EnergyView>& views,
                                               OverlapForm form)
    : surface_(surface),
      views_(views),
      form_(form),
      scale_(1.0 / std::sqrt(static_cast<double>(std::max<size_t>(views.size(), 1)))) {
  std::vector<std::vector<std::pair<int, int>>> seen_by(surface.size());
  for (int c = 0; c < static_cast<int>(views.size()); ++c) {
    const std::vector<int>& ids = views[c].pairs.surface_ids;
    for (int row = 0; row < static_cast<int>(ids.size()); ++row) {
      seen_by[ids[row]].emplace_back(c, row);
    }
  }
  for (int s = 0; s < surface.size(); ++s) {
    if (seen_by[s].empty()) continue;
    blocks_.push_back({{s}, 3 * static_cast<int>(seen_by[s].size())});
    observation_begin_.push_back(static_cast<int>(observations_.size()));
    observations_.insert(observations_.end(), seen_by[s].begin(), seen_by[s].end());
  }
  observation_begin_.push_back(static_cast<int>(observations_.size()));
}

Eigen::Vector3d ImageColorOfPairs(const EnergyView& view, const SurfaceGaussians& surface, int row,
                                  double k, OverlapForm form, const Eigen::Vector3d& fallback,
                                  Eigen::Vector3d* derivative, double reach_sigmas) {
  const CameraPairs& pairs = view.pairs;
  const int s = pairs.surface_ids[row];
  const ProjectedGaussian projected = ProjectSurfaceGaussian(
      view.camera, surface.base.col(s), surface.normals.col(s), k, surface.sigma_hat);
  ColorAccumulator accumulator(fallback);
  for (int p = pairs.begin[row]; p < pairs.begin[row + 1]; ++p) {
    const ImageGaussian& g = (*view.image)[pairs.image_ids[p]];
    const double reach2 = reach_sigmas * reach_sigmas *
                          (projected.sigma * projected.sigma + double(g.sigma) * g.sigma);
    const double d2 = (Eigen::Vector2d(g.x, g.y) - projected.mean).squaredNorm();
    if (reach_sigmas > 0.0 && d2 > reach2) continue;
    accumulator.Add(form, projected, g, derivative != nullptr);
  }
  if (derivative != nullptr) *derivative = accumulator.MeanDerivative();
  return accumulator.Mean();
}

void SurfaceColorSimilarity::Residual(int camera, int row, double k, Eigen::Vector3d* residual,
                                      Eigen::Vector3d* derivative) const {
  const EnergyView& view = views_[camera];
  const Eigen::Vector3d own = surface_.colors[view.pairs.surface_ids[row]].cast<double>();
  const Eigen::Vector3d predicted =
      ImageColorOfPairs(view, surface_, row, k, form_, own, derivative);
  *residual = scale_ * (predicted - own);
  if (derivative != nullptr) *derivative *= scale_;
}

double SurfaceColorSimilarity::Evaluate(const Eigen::VectorXd& k, Eigen::VectorXd* gradient) const {
  if (gradient != nullptr) *gradient = Eigen::VectorXd::Zero(k.size());
  const int num_blocks = static_cast<int>(blocks_.size());
  double sum_of_squares = 0.0;
#pragma omp parallel for schedule(dynamic, 64) reduction(+ : sum_of_squares)
  for (int b = 0; b < num_blocks; ++b) {
    const int s = blocks_[b].parameters[0];
    double dcost = 0.0;
    for (int o = observation_begin_[b]; o < observation_begin_[b + 1]; ++o) {
      Eigen::Vector3d residual, derivative;
      Residual(observations_[o].first, observations_[o].second, k[s], &residual,
               gradient ? &derivative : nullptr);
      sum_of_squares += residual.squaredNorm();
      if (gradient != nullptr) dcost += residual.dot(derivative);
    }
    // Each block owns one parameter: no two threads write the same entry.
    if (gradient != nullptr) (*gradient)[s] = -dcost;
  }
  return -0.5 * sum_of_squares;
}

void SurfaceColorSimilarity::PrepareResiduals(const Eigen::VectorXd& k, bool with_jacobians) {
  const int num_observations = static_cast<int>(observations_.size());
  residuals_.resize(num_observations);
  derivatives_.resize(num_observations);
  const int num_blocks = static_cast<int>(blocks_.size());
#pragma omp parallel for schedule(dynamic, 64)
  for (int b = 0; b < num_blocks; ++b) {
    const int s = blocks_[b].parameters[0];
    for (int o = observation_begin_[b]; o < observation_begin_[b + 1]; ++o) {
      Residual(observations_[o].first, observations_[o].second, k[s], &residuals_[o],
               with_jacobians ? &derivatives_[o] : nullptr);
    }
  }
}

void SurfaceColorSimilarity::BlockResiduals(int block, double* residuals, double* jacobian) const {
  const int begin = observation_begin_[block];
  for (int o = begin; o < observation_begin_[block + 1]; ++o) {
    for (int channel = 0; channel < 3; ++channel) {
      residuals[3 * (o - begin) + channel] = residuals_[o][channel];
      if (jacobian != nullptr) jacobian[3 * (o - begin) + channel] = derivatives_[o][channel];
    }
  }
}

}  // namespace finecap
