// Smoothing a triangle mesh without changing its topology: Taubin's lambda|mu filter
// (G. Taubin, "A signal processing approach to fair surface design", SIGGRAPH 1995), which takes
// away the fine detail of a surface without shrinking it the way plain Laplacian smoothing does.
//
// What it is for: the synthetic generator's smoothed-input captures, whose coarse meshes are
// smoothed copies of the true surface (the paper's smoothed-input experiment), so any detailed
// mesh sequence becomes a benchmark with ground truth.
#ifndef FINECAP_GEOMETRY_MESH_SMOOTHING_H_
#define FINECAP_GEOMETRY_MESH_SMOOTHING_H_

#include <string>

#include <Eigen/Core>

#include "finecap/geometry/mesh.h"
#include "finecap/util/option_fields.h"

namespace finecap {

// One step moves each vertex by `factor` times the part of its Laplacian (the cotangent-weighted
// mean of its neighbours minus the vertex) that lies along its current normal; an iteration is a
// step with `lambda` (shrinks) followed by one with `mu` (negative: inflates back). Detail whose
// wavelength spans a few edges is damped by a constant factor per iteration, while shapes much
// larger than an edge pass almost unchanged (for lambda + mu < 0). The fields are documented
// where Fields() declares them (docs/configuration.md: synth.smoothing); the comments below add
// what the documentation does not say.
struct TaubinSmoothingOptions {
  // On a regular grid, a wave spanning w edges is damped per iteration by about
  // (1 - lambda k)(1 - mu k) with k = 1 - cos(2 pi / w): with the defaults 0.75 for w = 4, 0.94
  // for w = 6, 0.98 for w = 8 and 0.997 for w = 13, while waves with k below Taubin's pass band
  // 1 / lambda + 1 / mu (0.01: w > 44) keep their size.
  int iterations = 30;
  double lambda = 0.5;
  // -0.5025 makes the pass band small (0.01), and the largest shapes neither shrink nor grow (0
  // gives plain Laplacian smoothing, which shrinks; Taubin's -0.53 with lambda 0.5 grows a tube
  // of 48 edges around by 0.15 % in 20 iterations).
  double mu = -0.5025;

  static const OptionFields<TaubinSmoothingOptions>& Fields();  // option_fields.h
  // Throws Error naming `where` + ".iterations", ".lambda" or ".mu" for a value out of range, or
  // a lambda and mu that together make the filter unstable (some detail would grow instead of
  // fading: (1 - 2 lambda)(1 - 2 mu) < -1).
  void Check(const std::string& where) const;
};

// The vertices of `mesh` after Taubin smoothing; the faces stay as they are. Why only along the
// normal: the Laplacian of an unevenly sampled surface also points along the surface, and
// following it would slide the vertices over the surface (tangential drift), so that a vertex
// would no longer stand for the same point of the surface; the normal part alone removes bumps
// and leaves the sampling in place. Cotangent weights (those of the Laplace-Beltrami operator;
// clamped at zero, uniform for a vertex whose weights sum to zero) make the smoothing follow the
// surface's shape in metres rather than how it happens to be triangulated. Boundary vertices are
// smoothed like the others; vertices in no triangle keep their place. Throws Error (through
// options.Check("TaubinSmoothingOptions")) on invalid options.
Eigen::Matrix3Xd TaubinSmooth(const Mesh& mesh, const TaubinSmoothingOptions& options);

}  // namespace finecap

#endif  // FINECAP_GEOMETRY_MESH_SMOOTHING_H_
