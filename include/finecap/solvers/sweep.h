// A starting point for the solvers, found the way plane-sweep stereo finds depth: the data term
// is evaluated for every surface Gaussian at a few displacements spanning [-k_max, k_max] (all
// at once, since each evaluation moves every Gaussian by the same k), the per-Gaussian costs are
// smoothed over the mesh's neighbours so that a single colour coincidence cannot win, and each
// Gaussian starts at its best displacement. The local solvers then start inside the right basin
// instead of at k = 0, where the nearest optimum of a textured surface is often a wrong one (the
// paper's "risk of returning local maxima").
#ifndef FINECAP_SWEEP_H_
#define FINECAP_SWEEP_H_

#include <Eigen/Core>

#include "finecap/energy/frame_energy.h"
#include "finecap/util/option_fields.h"

namespace finecap {

// The plane sweep's options. The fields are documented where Fields() declares them
// (docs/configuration.md: refine.sweep); the comments below add what the documentation does not
// say.
struct SweepOptions {
  // The bounds of `samples` when the sweep is on: fewer than 3 displacements would not include
  // k = 0 and both signs.
  static constexpr int kMinSamples = 3;
  static constexpr int kMaxSamples = 1000;

  // Displacements in [-k_max, k_max]. 33: with the consensus similarity's tabulated colours a
  // sample costs little, and a start from the best displacement of each patch reaches inputs
  // farther from the truth (the temple's visual hull).
  int samples = 33;
  int smoothing_rounds = 4;

  static const OptionFields<SweepOptions>& Fields();  // option_fields.h
  void Check() const;
};

// The starting k (one entry per surface Gaussian, metres). The cost of a Gaussian at a
// displacement is the sum of squares of the residual blocks it belongs to, shared equally
// among the block's parameters.
Eigen::VectorXd SweepInitialization(FrameEnergy* energy, const SweepOptions& options);

}  // namespace finecap

#endif  // FINECAP_SWEEP_H_
