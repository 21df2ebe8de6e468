#include "finecap/model/gaussian_pairs.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "finecap/model/gaussian_overlap.h"
#include "model/surface_projection.h"

namespace finecap {
namespace {

// The image Gaussians that surface Gaussian s can reach for some k in [-k_max, k_max].
void ReachableImageGaussians(const Camera& camera, const ImageGaussians& image,
                             const SurfaceGaussians& surface, int s, const PairOptions& options,
                             std::vector<int>* reached) {
  const Eigen::Vector3d base = surface.base.col(s), normal = surface.normals.col(s);
  const ProjectedGaussian low =
      ProjectSurfaceGaussian(camera, base, normal, -options.k_max, surface.sigma_hat);
  const ProjectedGaussian high =
      ProjectSurfaceGaussian(camera, base, normal, options.k_max, surface.sigma_hat);
  // sigma_s is largest at the nearest end of the segment.
  const double sigma_s = std::max(low.sigma, high.sigma);
  image.FindReachingSegment(low.mean, high.mean, sigma_s, options.reach_sigmas, reached);
}

// The pairs of surface Gaussian s: image Gaussians in reach with a non-zero colour weight (and
// their weights), or, without colour weights, every image Gaussian in reach.
void PairsOf(const Camera& camera, const ImageGaussians& image, const SurfaceGaussians& surface,
             int s, const PairOptions& options, std::vector<int>* reached, std::vector<int>* ids,
             std::vector<float>* weights) {
  ReachableImageGaussians(camera, image, surface, s, options, reached);
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
    std::vector<int> reached, ids;
    std::vector<float> weights;
#pragma omp for schedule(dynamic, 16)
    for (int j = 0; j < n; j += step) {
      ids.clear();
      weights.clear();
      PairsOf(camera, image, surface, visible_ids[j], options, &reached, &ids, &weights);
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
  // Runs of consecutive surface Gaussians, built in parallel, each into lists of its own, then
  // concatenated in order: a few hundred allocations instead of two per surface Gaussian.
  constexpr int kRun = 256;
  const int num_runs = (n + kRun - 1) / kRun;
  const auto run_end = [n](int run) { return std::min(n, (run + 1) * kRun); };
  std::vector<std::vector<int>> ids(num_runs);
  std::vector<std::vector<float>> weights(num_runs);
  pairs.begin.assign(n + 1, 0);
#pragma omp parallel
  {
    std::vector<int> reached;
#pragma omp for schedule(dynamic, 1)
    for (int run = 0; run < num_runs; ++run) {
      for (int j = run * kRun; j < run_end(run); ++j) {
        PairsOf(camera, image, surface, pairs.surface_ids[j], options, &reached, &ids[run],
                &weights[run]);
        pairs.begin[j + 1] = static_cast<int>(ids[run].size());  // Within the run, for now.
      }
    }
  }
  pairs.image_ids.reserve(
      std::accumulate(ids.begin(), ids.end(), size_t{0},
                      [](size_t sum, const auto& run) { return sum + run.size(); }));
  for (int run = 0; run < num_runs; ++run) {
    const int offset = static_cast<int>(pairs.image_ids.size());
    for (int j = run * kRun; j < run_end(run); ++j) pairs.begin[j + 1] += offset;
    pairs.image_ids.insert(pairs.image_ids.end(), ids[run].begin(), ids[run].end());
    pairs.color_weights.insert(pairs.color_weights.end(), weights[run].begin(), weights[run].end());
  }
  return pairs;
}

}  // namespace finecap
