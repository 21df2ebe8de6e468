// The Check() of the options structs of refinement (refine.h, energy_options.h, solver.h, sweep.h)
// and of the held-out score (heldout_score.h):
// pure validation, kept apart from the stages' code so that reading a config links none of the
// stages (the config fuzzer builds from the parser sources alone).
#include "finecap/energy_options.h"
#include "finecap/error.h"
#include "finecap/gaussian_overlap.h"
#include "finecap/heldout_score.h"
#include "finecap/refine.h"
#include "finecap/solver.h"
#include "finecap/sweep.h"

namespace finecap {

void RefineOptions::Check() const {
  Require(subdivision_levels >= 0 && subdivision_levels <= 4, "model.subdivision_levels",
          "must lie in [0, 4]");
  Require(sigma_hat > 0.0, "model.sigma_hat", "must be positive");
  Require(reference_colors == "pixels" || reference_colors == "image_model",
          "model.reference_colors", "must be pixels or image_model");
  image.Check();
  visibility.Check();
  energy.Check();
  solver.Check();
  sweep.Check();
  coarse_to_fine.Check();
}

void EnergyOptions::Check() const {
  Require(similarity == "paper" || similarity == "surface_color" || similarity == "consensus",
          "energy.similarity",
          "'" + similarity + "' is not one of: paper, surface_color, consensus");
  consensus.Check();
  ParseOverlapForm(overlap);
  Require(color_cutoff > 0.0, "energy.color_cutoff", "must be positive");
  Require(reach_sigmas > 0.0, "energy.reach_sigmas", "must be positive");
  Require(k_max > 0.0, "energy.k_max", "must be positive");
  Require(w_reg >= 0.0, "energy.w_reg", "must be non-negative");
  Require(w_prior >= 0.0, "energy.w_prior", "must be non-negative");
  Require(confidence_prior >= 0.0, "energy.confidence_prior", "must be non-negative");
  Require(confidence_threshold > 0.0, "energy.confidence_threshold", "must be positive");
  Require(confidence_opening >= 0, "energy.confidence_opening", "must be non-negative");
  Require(reg_rings >= 1, "energy.reg_rings", "must be at least 1");
  Require(reg_unit == "mm" || reg_unit == "m", "energy.reg_unit", "must be mm or m");
}

void ConsensusOptions::Check() const {
  Require(contrast_floor > 0.0, "energy.consensus.contrast_floor", "must be positive");
  Require(min_cameras >= 2, "energy.consensus.min_cameras", "must be at least 2");
  Require(passes >= 1, "energy.consensus.passes", "must be at least 1");
  Require(patch_rings >= 1, "energy.consensus.patch_rings", "must be at least 1");
  Require(robust_fraction >= 0.0, "energy.consensus.robust_fraction", "must be non-negative");
}

void SolverOptions::Check() const {
  Require(type == "ceres" || type == "gradient_ascent" || type == "lbfgs", "solver.type",
          "'" + type + "' is not one of: ceres, gradient_ascent, lbfgs");
  Require(max_iterations >= 0, "solver.max_iterations", "must be non-negative");
  Require(function_tolerance >= 0.0, "solver.function_tolerance", "must be non-negative");
  Require(num_threads >= 0, "solver.num_threads", "must be non-negative");
  Require(trust_region == "levenberg_marquardt" || trust_region == "dogleg", "solver.trust_region",
          "'" + trust_region + "' is not one of: levenberg_marquardt, dogleg");
  Require(linear_solver == "sparse_normal_cholesky" || linear_solver == "cgnr" ||
              linear_solver == "dense_qr",
          "solver.linear_solver",
          "'" + linear_solver + "' is not one of: sparse_normal_cholesky, cgnr, dense_qr");
  Require(initial_step > 0.0, "solver.initial_step", "must be positive");
  Require(step_growth >= 1.0, "solver.step_growth", "must be at least 1");
  Require(step_shrink > 0.0 && step_shrink < 1.0, "solver.step_shrink", "must lie in (0, 1)");
  Require(max_step > 0.0, "solver.max_step", "must be positive");
}

void SweepOptions::Check() const {
  Require(samples == 0 || samples >= 3, "solver.sweep_samples", "must be 0 (off) or at least 3");
  Require(smoothing_rounds >= 0, "solver.sweep_smoothing_rounds", "must be non-negative");
}

void CoarseToFineOptions::Check() const {
  Require(levels >= 1 && levels <= 5, "refine.coarse_to_fine.levels", "must lie in [1, 5]");
  Require(scale > 1.0 && scale <= 4.0, "refine.coarse_to_fine.scale", "must lie in (1, 4]");
}

void HeldOutOptions::Check() const {
  Require(neighbours >= 1, "validation.neighbours", "must be at least 1");
  Require(window >= 3 && window % 2 == 1, "validation.window", "must be an odd number >= 3");
  Require(min_std >= 0.0, "validation.min_std", "must be non-negative");
  Require(depth_tolerance_px > 0.0, "validation.depth_tolerance_px", "must be positive");
}

}  // namespace finecap
