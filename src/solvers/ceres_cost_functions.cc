#include "solvers/ceres_cost_functions.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include <Eigen/QR>

#include "solvers/solvers_internal.h"

namespace finecap {

SharedEvaluationCallback::SharedEvaluationCallback(SimilarityTerm* term, const Eigen::VectorXd* k,
                                                   double* seconds)
    : term_(term), k_(k), seconds_(seconds), summaries_only_(true) {
  for (const SimilarityTerm::ResidualBlock& block : term->residual_blocks()) {
    if (block.parameters.size() != 1) summaries_only_ = false;
  }
}

void SharedEvaluationCallback::PrepareForEvaluation(bool /*evaluate_jacobians*/,
                                                    bool new_evaluation_point) {
  // Each step's candidate is evaluated for its cost alone and, once the step is taken, again
  // with Jacobians at the same point (Ceres says so); a step is mostly taken, so one preparation
  // with Jacobians serves both. Comparing the point itself also catches a point Ceres evaluates
  // again without saying so.
  if (!new_evaluation_point || (prepared_.size() == k_->size() && prepared_ == *k_)) return;
  const internal::Stopwatch clock;
  if (summaries_only_) {
    term_->PrepareBlockSummaries(*k_);
  } else {
    term_->SimilarityTerm::PrepareBlockSummaries(*k_);
  }
  prepared_ = *k_;
  *seconds_ += clock.Seconds();
}

SimilarityBlockCost::SimilarityBlockCost(const SimilarityTerm& term, int block)
    : term_(term), block_(block) {
  const SimilarityTerm::ResidualBlock& info = term.residual_blocks()[block];
  set_num_residuals(info.num_residuals);
  mutable_parameter_block_sizes()->assign(info.parameters.size(), 1);
}

bool SimilarityBlockCost::Evaluate(double const* const* /*parameters*/, double* residuals,
                                   double** jacobians) const {
  if (jacobians == nullptr) {
    term_.BlockResiduals(block_, residuals, nullptr);
    return true;
  }
  // The term writes a row-major residuals x parameters matrix; Ceres wants one column per
  // parameter block.
  const int num_parameters = static_cast<int>(parameter_block_sizes().size());
  thread_local std::vector<double> jacobian;
  jacobian.resize(static_cast<size_t>(num_residuals()) * num_parameters);
  term_.BlockResiduals(block_, residuals, jacobian.data());
  for (int p = 0; p < num_parameters; ++p) {
    if (jacobians[p] == nullptr) continue;
    for (int r = 0; r < num_residuals(); ++r) jacobians[p][r] = jacobian[r * num_parameters + p];
  }
  return true;
}

ReducedSimilarityBlockCost::ReducedSimilarityBlockCost(const SimilarityTerm& term, int block,
                                                       bool secant)
    : term_(term), block_(block), full_(term, block), secant_(secant) {
  const SimilarityTerm::ResidualBlock& info = term.residual_blocks()[block];
  num_full_residuals_ = info.num_residuals;
  const int num_parameters = static_cast<int>(info.parameters.size());
  set_num_residuals(num_parameters == 1 ? 2 : std::min(num_full_residuals_, num_parameters + 1));
  mutable_parameter_block_sizes()->assign(num_parameters, 1);
}

bool ReducedSimilarityBlockCost::Evaluate(double const* const* parameters, double* residuals,
                                          double** jacobians) const {
  const int p = static_cast<int>(parameter_block_sizes().size());
  if (p == 1) {
    EvaluateOneParameter(parameters[0][0], residuals, jacobians);
    return true;
  }
  const int m = num_full_residuals_;
  thread_local Eigen::VectorXd r;
  thread_local Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> jacobian;
  r.resize(m);
  if (m == num_residuals()) return full_.Evaluate(parameters, residuals, jacobians);
  std::fill_n(residuals, num_residuals(), 0.0);
  if (jacobians == nullptr) {
    term_.BlockResiduals(block_, r.data(), nullptr);
    residuals[0] = r.norm();
    return true;
  }
  jacobian.resize(m, p);
  term_.BlockResiduals(block_, r.data(), jacobian.data());
  const double squared_norm = r.squaredNorm();
  Eigen::MatrixXd reduced = Eigen::MatrixXd::Zero(p + 1, p);  // [R; 0].
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(jacobian);
  const Eigen::VectorXd along = (qr.householderQ().transpose() * r).head(p);  // Q^T r.
  reduced.topRows(p) = qr.matrixQR().topRows(p).triangularView<Eigen::Upper>();
  for (int i = 0; i < p; ++i) residuals[i] = along[i];
  // What of r no step can reduce; rounding may make the difference a hair negative.
  residuals[p] = std::sqrt(std::max(0.0, squared_norm - along.squaredNorm()));
  for (int q = 0; q < p; ++q) {
    if (jacobians[q] == nullptr) continue;
    for (int i = 0; i <= p; ++i) jacobians[q][i] = reduced(i, q);
  }
  return true;
}

double ReducedSimilarityBlockCost::ModelCurvature(
    double k, const SimilarityTerm::BlockSummary& summary) const {
  if (!secant_) return summary.curvature;
  // Steps shorter than this (metres) are rounding: their secant is noise.
  constexpr double kMinSpan = 1e-9;
  const bool moved = !has_last_ || std::abs(k - last_k_) > kMinSpan;
  double curvature = summary.curvature;
  if (has_last_ && moved) {
    const double secant = (summary.gradient - last_gradient_) / (k - last_k_);
    curvature = std::clamp(secant, kMinSecantFactor * summary.curvature,
                           kMaxSecantFactor * summary.curvature);
    // J^T J >= g^2 / |r|^2 always (Cauchy-Schwarz); a lower h must not go below it.
    if (summary.squared_norm > 0.0) {
      curvature = std::max(curvature, summary.gradient * summary.gradient / summary.squared_norm);
    }
  }
  if (moved) {
    has_last_ = true;
    last_k_ = k;
    last_gradient_ = summary.gradient;
  }
  return curvature;
}

void ReducedSimilarityBlockCost::EvaluateOneParameter(double k, double* residuals,
                                                      double** jacobians) const {
  const SimilarityTerm::BlockSummary& summary = term_.BlockSummaryOf(block_);
  if (jacobians == nullptr) {
    residuals[0] = std::sqrt(summary.squared_norm);
    residuals[1] = 0.0;
    return;
  }
  // R = sqrt(h) and Q^T r = J^T r / R, h = J^T J but for the secant.
  const double length = std::sqrt(ModelCurvature(k, summary));
  residuals[0] = length > 0.0 ? summary.gradient / length : 0.0;
  // What of r no step can reduce; rounding may make the difference a hair negative.
  residuals[1] = std::sqrt(std::max(0.0, summary.squared_norm - residuals[0] * residuals[0]));
  if (jacobians[0] != nullptr) {
    jacobians[0][0] = length;
    jacobians[0][1] = 0.0;
  }
}

IsolatedSimilarityBlockCost::IsolatedSimilarityBlockCost(SimilarityTerm* term, int block,
                                                         const Eigen::VectorXd& k)
    : SimilarityBlockCost(*term, block), mutable_term_(term), k_(k) {}

bool IsolatedSimilarityBlockCost::Evaluate(double const* const* parameters, double* residuals,
                                           double** jacobians) const {
  Eigen::VectorXd k = k_;
  const std::vector<int>& ids = term_.residual_blocks()[block_].parameters;
  for (size_t p = 0; p < ids.size(); ++p) k[ids[p]] = parameters[p][0];
  mutable_term_->PrepareResiduals(k, jacobians != nullptr);
  return SimilarityBlockCost::Evaluate(parameters, residuals, jacobians);
}

SmoothnessBlockCost::SmoothnessBlockCost(double prior_root, std::vector<Neighbour> neighbours,
                                         int num_free)
    : prior_root_(prior_root), neighbours_(std::move(neighbours)) {
  set_num_residuals(static_cast<int>(neighbours_.size()) + (prior_root_ > 0.0 ? 1 : 0));
  mutable_parameter_block_sizes()->assign(1 + num_free, 1);
}

bool SmoothnessBlockCost::Evaluate(double const* const* parameters, double* residuals,
                                   double** jacobians) const {
  const int num_parameters = static_cast<int>(parameter_block_sizes().size());
  const double k = parameters[0][0];
  if (jacobians != nullptr) {
    for (int p = 0; p < num_parameters; ++p) {
      if (jacobians[p] != nullptr) std::fill_n(jacobians[p], num_residuals(), 0.0);
    }
  }
  int r = 0;
  if (prior_root_ > 0.0) {
    residuals[r] = prior_root_ * k;
    if (jacobians != nullptr && jacobians[0] != nullptr) jacobians[0][r] = prior_root_;
    ++r;
  }
  for (const Neighbour& neighbour : neighbours_) {
    const double other = neighbour.parameter >= 0 ? parameters[neighbour.parameter][0] : 0.0;
    residuals[r] = neighbour.coefficient * (k - other);
    if (jacobians != nullptr) {
      if (jacobians[0] != nullptr) jacobians[0][r] = neighbour.coefficient;
      if (neighbour.parameter >= 0 && jacobians[neighbour.parameter] != nullptr) {
        jacobians[neighbour.parameter][r] = -neighbour.coefficient;
      }
    }
    ++r;
  }
  return true;
}

}  // namespace finecap
