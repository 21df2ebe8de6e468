// Which pairs of surface and image Gaussians the energy evaluates in one camera.
//
// A pair matters only when the two Gaussians can overlap: their means closer than reach_sigmas
// combined standard deviations for some k in [-k_max, k_max]. The list is built once per frame,
// for the whole allowed range of k, so the structure of the problem stays fixed during a solve,
// and each evaluation runs over a flat list instead of querying a spatial index again.
#ifndef FINECAP_GAUSSIAN_PAIRS_H_
#define FINECAP_GAUSSIAN_PAIRS_H_

#include <vector>

#include "finecap/geometry/camera.h"
#include "finecap/model/image_gaussians.h"
#include "finecap/model/surface_gaussians.h"

namespace finecap {

// The pairs of one camera, grouped by surface Gaussian (compressed rows).
struct CameraPairs {
  std::vector<int> surface_ids;  // Surface Gaussians visible in the camera, ascending.
  // The pairs of surface_ids[j] are image_ids[begin[j] .. begin[j + 1]).
  std::vector<int> begin;
  std::vector<int> image_ids;
  // T(|eta_i - eta_s|) of each pair; pairs whose weight is zero are left out. Empty when the
  // pairs were built without colour weights (every weight 1): a frame's pair lists hold millions
  // of pairs.
  std::vector<float> color_weights;

  int num_pairs() const { return static_cast<int>(image_ids.size()); }
  float color_weight(int pair) const { return color_weights.empty() ? 1.0f : color_weights[pair]; }
};

struct PairOptions {
  double k_max = 0.02;        // Metres.
  double reach_sigmas = 3.0;  // Combined standard deviations.
  // Cut-off D of the colour weight; <= 0 keeps every pair with weight 1.
  double color_cutoff = 0.05;
};

// `visible[s]` says whether the camera sees surface Gaussian s.
CameraPairs BuildCameraPairs(const Camera& camera, const ImageGaussians& image,
                             const SurfaceGaussians& surface,
                             const std::vector<unsigned char>& visible, const PairOptions& options);

// The number of pairs BuildCameraPairs would make, from the pairs of every `stride`-th visible
// surface Gaussian scaled to all of them (stride 1: exact), without keeping any: what a frame's
// pair lists will weigh, known before they are built.
double CountCameraPairs(const Camera& camera, const ImageGaussians& image,
                        const SurfaceGaussians& surface, const std::vector<unsigned char>& visible,
                        const PairOptions& options, int stride);

}  // namespace finecap

#endif  // FINECAP_GAUSSIAN_PAIRS_H_
