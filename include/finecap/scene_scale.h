// A guard against captures in the wrong unit. finecap's lengths are metres (sigma_hat, k_max, the
// depth tolerance, the synthetic folds), so a capture in millimetres or centimetres would not fail
// anywhere: its Gaussians would simply be 1000 or 100 times too small to see anything, and the
// refinement would silently do nothing useful. The size of the coarse mesh against sigma_hat
// tells the units apart: a performer in metres spans a few hundred sigma_hat.
#ifndef FINECAP_SCENE_SCALE_H_
#define FINECAP_SCENE_SCALE_H_

#include <string>

#include "finecap/mesh.h"

namespace finecap {

struct SceneScaleLimits {
  // The smallest bounding-box diagonal of a coarse mesh accepted, in multiples of sigma_hat.
  // Default 5 (3.5 cm with the default sigma_hat of 7 mm): smaller, a surface Gaussian covers
  // the whole subject. Must be positive.
  double min_sigmas = 5.0;
  // The largest, in multiples of sigma_hat. Default 3000 (21 m with the default sigma_hat): a
  // 1.7 m performer spans ~300; the same performer in centimetres ~30,000, in millimetres
  // ~300,000. Must exceed min_sigmas.
  double max_sigmas = 3000.0;

  void Check() const;
};

// The diagonal of the axis-aligned bounding box of `mesh`'s vertices, in the mesh's units.
double BoundingBoxDiagonal(const Mesh& mesh);

// Throws Error(where, ...) when the bounding-box diagonal of `mesh` lies outside
// [limits.min_sigmas, limits.max_sigmas] * sigma_hat, saying how large the mesh is, which unit it
// looks like and what to do (convert the capture to metres, or change model.sigma_hat for a
// subject of unusual size). `where` should name the mesh file. `sigma_hat` must be positive.
void RequirePlausibleSceneScale(const Mesh& mesh, double sigma_hat, const std::string& where,
                                const SceneScaleLimits& limits = {});

}  // namespace finecap

#endif  // FINECAP_SCENE_SCALE_H_
