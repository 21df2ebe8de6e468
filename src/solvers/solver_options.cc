// The Check() of the solvers' options (solver.h, sweep.h) and the names of their choices
// (enum_names.h): pure validation, apart from the solvers' code. Each Check() names the C++ field
// it refuses; its ranges are the config schema's (config_options_test walks the schema and holds
// them to it).
#include <string>

#include "finecap/solvers/solver.h"
#include "finecap/solvers/sweep.h"
#include "finecap/util/error.h"
#include "util/option_checks.h"

namespace finecap {

using internal::RequireFieldRange;
using internal::RequireKnownChoice;

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

void SolverOptions::Check() const {
  RequireKnownChoice(type, "SolverOptions::type");
  RequireFieldRange(max_iterations, 0, 100000, "SolverOptions::max_iterations");
  RequireFieldRange(function_tolerance, 0.0, 1.0, "SolverOptions::function_tolerance");
  Require(num_threads >= 0, "SolverOptions::num_threads", "must be non-negative (0: all cores)");
  RequireKnownChoice(trust_region, "SolverOptions::trust_region");
  RequireKnownChoice(linear_solver, "SolverOptions::linear_solver");
  RequireKnownChoice(curvature, "SolverOptions::curvature");
  // Ceres' dogleg needs the exact Gauss-Newton step, which conjugate gradients do not give.
  Require(type != SolverType::kCeres || trust_region != TrustRegionType::kDogleg ||
              linear_solver != LinearSolverType::kCgnr,
          "SolverOptions::trust_region",
          "dogleg needs an exact linear solver (sparse_normal_cholesky or dense_qr), not cgnr");
  RequireFieldRange(initial_step, 1e-9, 1.0, "SolverOptions::initial_step");
  RequireFieldRange(step_growth, 1.0, 10.0, "SolverOptions::step_growth");
  RequireFieldRange(step_shrink, 1e-3, 0.999, "SolverOptions::step_shrink");
  RequireFieldRange(max_step, 1e-9, 1.0, "SolverOptions::max_step");
}

void SweepOptions::Check() const {
  // Fewer than 3 displacements would not include k = 0 and both signs.
  Require(samples == 0 || (samples >= kMinSamples && samples <= kMaxSamples),
          "SweepOptions::samples",
          "is " + std::to_string(samples) + " but must be 0 (off) or lie in [" +
              std::to_string(kMinSamples) + ", " + std::to_string(kMaxSamples) + "]");
  RequireFieldRange(smoothing_rounds, 0, 1000, "SweepOptions::smoothing_rounds");
}

}  // namespace finecap
