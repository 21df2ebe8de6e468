#include "finecap/model/gaussian_pairs.h"

#include <algorithm>
#include <cmath>

#include "finecap/model/gaussian_overlap.h"
#include "model/surface_projection.h"

namespace finecap {
namespace {

// Squared distance from point p to the segment [a, b].
double SquaredDistanceToSegment(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                                const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double length2 = ab.squaredNorm();
  const double t = length2 > 0.0 ? std::clamp((p - a).dot(ab) / length2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).squaredNorm();
}

// The image Gaussians that surface Gaussian s can reach for some k in [-k_max, k_max].
void ReachableImageGaussians(const Camera& camera, const ImageGaussians& image,
                             const SurfaceGaussians& surface, int s, const PairOptions& options,
                             std::vector<int>* candidates, std::vector<int>* reached) {
  const Eigen::Vector3d base = surface.base.col(s), normal = surface.normals.col(s);
  const ProjectedGaussian low =
      ProjectSurfaceGaussian(camera, base, normal, -options.k_max, surface.sigma_hat);
  const ProjectedGaussian high =
      ProjectSurfaceGaussian(camera, base, normal, options.k_max, surface.sigma_hat);
  // sigma_s is largest at the nearest end of the segment.
  const double sigma_s = std::max(low.sigma, high.sigma);
  const double cutoff = options.reach_sigmas;
  const Eigen::Vector2d middle = 0.5 * (low.mean + high.mean);
  const double half_length = 0.5 * (high.mean - low.mean).norm();
  // (h + c a)^2 <= 2 (h^2 + c^2 a^2) for a = sqrt(sigma_s^2 + sigma_i^2): a query from the middle
  // of the segment with sigma sqrt(sigma_s^2 + (h/c)^2) and cut-off sqrt(2) c finds a superset of
  // the image Gaussians within c*a of the segment, which the exact test below then filters.
  const double query_sigma = std::sqrt(sigma_s * sigma_s + std::pow(half_length / cutoff, 2));
  image.FindReaching(middle, query_sigma, std::sqrt(2.0) * cutoff, candidates);
  reached->clear();
  for (int i : *candidates) {
    const ImageGaussian& g = image[i];
    const double reach2 = cutoff * cutoff * (sigma_s * sigma_s + double(g.sigma) * g.sigma);
    if (SquaredDistanceToSegment(Eigen::Vector2d(g.x, g.y), low.mean, high.mean) <= reach2) {
      reached->push_back(i);
    }
  }
  std::sort(reached->begin(), reached->end());
}

// The pairs of surface Gaussian s: image Gaussians in reach with a non-zero colour weight (and
// their weights), or, without colour weights, every image Gaussian in reach.
void PairsOf(const Camera& camera, const ImageGaussians& image, const SurfaceGaussians& surface,
             int s, const PairOptions& options, std::vector<int>* candidates,
             std::vector<int>* reached, std::vector<int>* ids, std::vector<float>* weights) {
  ReachableImageGaussians(camera, image, surface, s, options, candidates, reached);
  if (options.color_cutoff <= 0.0) {
    ids->insert(ids->end(), reached->begin(), reached->end());
    return;
  }
  for (int i : *reached) {
    const double weight =
        Wendland(ColorDistance(image[i].Color(), surface.colors[s], surface.color_space),
                 options.color_cutoff);
    if (weight <= 0.0) continue;
    ids->push_back(i);
    weights->push_back(static_cast<float>(weight));
  }
}

}  // namespace

double CountCameraPairs(const Camera& camera, const ImageGaussians& image,
                        const SurfaceGaussians& surface, const std::vector<unsigned char>& visible,
                        const PairOptions& options, int stride) {
  std::vector<int> visible_ids;
  for (int s = 0; s < surface.size(); ++s) {
    if (visible[s]) visible_ids.push_back(s);
  }
  const int n = static_cast<int>(visible_ids.size());
  const int step = std::max(1, stride);
  long counted = 0, sampled = 0;
#pragma omp parallel reduction(+ : counted, sampled)
  {
    std::vector<int> candidates, reached, ids;
    std::vector<float> weights;
#pragma omp for schedule(dynamic, 16)
    for (int j = 0; j < n; j += step) {
      ids.clear();
      weights.clear();
      PairsOf(camera, image, surface, visible_ids[j], options, &candidates, &reached, &ids,
              &weights);
      counted += static_cast<long>(ids.size());
      ++sampled;
    }
  }
  return sampled > 0 ? double(counted) * n / sampled : 0.0;
}

CameraPairs BuildCameraPairs(const Camera& camera, const ImageGaussians& image,
                             const SurfaceGaussians& surface,
                             const std::vector<unsigned char>& visible,
                             const PairOptions& options) {
  CameraPairs pairs;
  for (int s = 0; s < surface.size(); ++s) {
    if (visible[s]) pairs.surface_ids.push_back(s);
  }
  const int n = static_cast<int>(pairs.surface_ids.size());
  // Per surface Gaussian lists, built in parallel, then concatenated in order.
  std::vector<std::vector<int>> ids(n);
  std::vector<std::vector<float>> weights(n);
#pragma omp parallel
  {
    std::vector<int> candidates, reached;
#pragma omp for schedule(dynamic, 64)
    for (int j = 0; j < n; ++j) {
      PairsOf(camera, image, surface, pairs.surface_ids[j], options, &candidates, &reached, &ids[j],
              &weights[j]);
    }
  }
  pairs.begin.assign(n + 1, 0);
  for (int j = 0; j < n; ++j) pairs.begin[j + 1] = pairs.begin[j] + static_cast<int>(ids[j].size());
  pairs.image_ids.reserve(pairs.begin[n]);
  for (int j = 0; j < n; ++j) {
    pairs.image_ids.insert(pairs.image_ids.end(), ids[j].begin(), ids[j].end());
  }
  if (options.color_cutoff > 0.0) {
    pairs.color_weights.reserve(pairs.begin[n]);
    for (int j = 0; j < n; ++j) {
      pairs.color_weights.insert(pairs.color_weights.end(), weights[j].begin(), weights[j].end());
    }
  }
  return pairs;
}

}  // namespace finecap
