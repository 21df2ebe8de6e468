// The solvers' options (solver.h, sweep.h): the declaration of their fields (option_fields.h),
// their Check() and the names of their choices (enum_names.h); pure validation, apart from the
// solvers' code.
#include <string>

#include "finecap/solvers/solver.h"
#include "finecap/solvers/sweep.h"
#include "finecap/util/error.h"

namespace finecap {

const std::vector<EnumName<SolverType>>& EnumNames(SolverType) {
  static const std::vector<EnumName<SolverType>> names = {
      {SolverType::kCeres, "ceres"},
      {SolverType::kGradientAscent, "gradient_ascent"},
      {SolverType::kLbfgs, "lbfgs"}};
  return names;
}

const std::vector<EnumName<TrustRegionType>>& EnumNames(TrustRegionType) {
  static const std::vector<EnumName<TrustRegionType>> names = {
      {TrustRegionType::kLevenbergMarquardt, "levenberg_marquardt"},
      {TrustRegionType::kDogleg, "dogleg"}};
  return names;
}

const std::vector<EnumName<LinearSolverType>>& EnumNames(LinearSolverType) {
  static const std::vector<EnumName<LinearSolverType>> names = {
      {LinearSolverType::kSparseNormalCholesky, "sparse_normal_cholesky"},
      {LinearSolverType::kCgnr, "cgnr"},
      {LinearSolverType::kDenseQr, "dense_qr"}};
  return names;
}

const std::vector<EnumName<CurvatureModel>>& EnumNames(CurvatureModel) {
  static const std::vector<EnumName<CurvatureModel>> names = {
      {CurvatureModel::kGaussNewton, "gauss_newton"}, {CurvatureModel::kSecant, "secant"}};
  return names;
}

const OptionFields<SolverOptions>& SolverOptions::Fields() {
  static const OptionFields<SolverOptions> fields = [] {
    OptionFields<SolverOptions> f;
    f.AddEnum("type", &SolverOptions::type,
              "ceres (least squares, Levenberg-Marquardt), gradient_ascent (the paper's) or "
              "lbfgs.");
    f.AddInt("max_iterations", &SolverOptions::max_iterations,
             "Most iterations per frame (the paper's ascent: 150).", 0, 100000);
    f.AddDouble("function_tolerance", &SolverOptions::function_tolerance,
                "Stop when the energy changes by less than this fraction.", 0.0, 1.0);
    f.AddEnum("trust_region", &SolverOptions::trust_region, "Ceres' trust-region strategy.");
    f.AddEnum("linear_solver", &SolverOptions::linear_solver,
              "Ceres' linear solver: sparse Cholesky (SuiteSparse), conjugate gradients on the "
              "normal equations, or dense QR (tiny problems only).");
    f.AddEnum("curvature", &SolverOptions::curvature,
              "Ceres: curvature of a similarity block's model, Gauss-Newton's J^T J or the secant "
              "of its gradient between its last two evaluations (within 0.3-3 J^T J).");
    f.AddDouble("initial_step", &SolverOptions::initial_step,
                "Gradient ascent: first step of the steepest k_s, m", 1e-9, 1.0);
    f.AddDouble("step_growth", &SolverOptions::step_growth,
                "Gradient ascent: step factor growth while a derivative keeps its sign.", 1.0,
                10.0);
    f.AddDouble("step_shrink", &SolverOptions::step_shrink,
                "Gradient ascent: step factor shrink when a derivative flips its sign.", 1e-3,
                0.999);
    f.AddDouble("max_step", &SolverOptions::max_step,
                "Gradient ascent: largest step of one k_s in one iteration, m", 1e-9, 1.0);
    return f;
  }();
  return fields;
}

void SolverOptions::Check() const {
  Fields().CheckValues(*this, "SolverOptions::");
  Require(num_threads >= 0, "SolverOptions::num_threads", "must be non-negative (0: all cores)");
  Require(type != SolverType::kCeres || trust_region != TrustRegionType::kDogleg ||
              linear_solver != LinearSolverType::kCgnr,
          "SolverOptions::trust_region",
          "dogleg needs an exact linear solver (sparse_normal_cholesky or dense_qr), not cgnr");
}

const OptionFields<SweepOptions>& SweepOptions::Fields() {
  static const OptionFields<SweepOptions> fields = [] {
    OptionFields<SweepOptions> f;
    f.AddIntOrOff("samples", &SweepOptions::samples,
                  "Plane-sweep start: displacements tried per surface Gaussian before solving "
                  "(0 = off, start at k = 0).",
                  kMinSamples, kMaxSamples);
    f.AddInt("smoothing_rounds", &SweepOptions::smoothing_rounds,
             "Plane-sweep start: rounds of averaging cost curves over mesh neighbours, counted on "
             "the input subdivided once (four times as many per further level: the same reach).",
             0, 1000);
    f.AddDouble("window_sigmas", &SweepOptions::window_sigmas,
                "Plane-sweep start: each surface Gaussian first looks for its lowest cost within "
                "this many model.sigma_hat of the input, and doubles its window only while that "
                "cost is at the window's end and falls further beyond it (0: the whole range).",
                0.0, 1e4);
    f.AddDouble("max_step_sigmas", &SweepOptions::max_step_sigmas,
                "Plane-sweep start: the displacements tried are at most this many "
                "model.sigma_hat apart, more of them than `samples` on a wide range (0: "
                "`samples` alone).",
                0.0, 100.0);
    f.AddDouble("widen_share", &SweepOptions::widen_share,
                "Plane-sweep start: a frame's range (energy.k_max) doubles while more than this "
                "share of its surface Gaussians finds its lowest cost at an end of the range "
                "(0: never widen).",
                0.0, 1.0);
    f.AddInt("max_widenings", &SweepOptions::max_widenings,
             "Plane-sweep start: doublings of a frame's range (energy.k_max) at most.", 0, 20);
    f.AddDouble("narrow_share", &SweepOptions::narrow_share,
                "Plane-sweep start: a frame's range (energy.k_max) that did not widen narrows to "
                "its narrowest halving, down to model.sigma_hat, in whose outer half fewer than "
                "this share of its surface Gaussians finds its lowest cost (0: never narrow).",
                0.0, 1.0);
    f.AddDouble("detail_range_sigmas", &SweepOptions::detail_range_sigmas,
                "Detail stage: before its first pass each surface Gaussian tries displacements "
                "within this many model.sigma_hat of where the surface Gaussians' stage left it, "
                "read at the images' own resolution, and starts from the lowest of their costs "
                "averaged over its neighbours (detail_smoothing_rounds); 0, samples 0 or "
                "solver.max_iterations 0: off.",
                0.0, 16.0);
    f.AddDouble("detail_step_sigmas", &SweepOptions::detail_step_sigmas,
                "Detail stage's sweep: the displacements tried are at most this many "
                "model.sigma_hat apart.",
                0.01, 4.0);
    f.AddInt("detail_smoothing_rounds", &SweepOptions::detail_smoothing_rounds,
             "Detail stage's sweep: rounds of averaging its costs over mesh neighbours, counted "
             "as smoothing_rounds are.",
             0, 1000);
    f.AddDouble("min_uniqueness", &SweepOptions::min_uniqueness,
                "Plane-sweep start: a surface Gaussian that at most two cameras see within "
                "visibility.max_view_angle_deg starts at the input instead of its lowest cost "
                "when that stands out by less than this fraction of its curve's median height "
                "above it against the lowest cost more than 2 model.sigma_hat away in its window "
                "(curves averaged over neighbours as smoothing_rounds says; 0: never).",
                0.0, 1.0);
    return f;
  }();
  return fields;
}

void SweepOptions::Check() const { Fields().CheckValues(*this, "SweepOptions::"); }

}  // namespace finecap
