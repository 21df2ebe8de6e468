#include "finecap/ceres_cost_functions.h"

#include <algorithm>
#include <utility>

#include "solvers/solvers_internal.h"

namespace finecap {

SharedEvaluationCallback::SharedEvaluationCallback(SimilarityTerm* term, const Eigen::VectorXd* k,
                                                   double* seconds)
    : term_(term), k_(k), seconds_(seconds) {}

void SharedEvaluationCallback::PrepareForEvaluation(bool evaluate_jacobians,
                                                    bool new_evaluation_point) {
  // Ceres' trust region with bounds evaluates each new point up to three times: the projected
  // line search's first trial (with Jacobians), the candidate's cost (residuals only), and, once
  // the step is taken, the Jacobians again; only the last says it is the same point. Comparing
  // the point itself lets one preparation with Jacobians serve all three. A residual-only
  // preparation cannot serve a later Jacobian request at the same point.
  const bool same_point =
      !new_evaluation_point || (prepared_.size() == k_->size() && prepared_ == *k_);
  if (same_point && (have_jacobians_ || !evaluate_jacobians)) return;
  const internal::Stopwatch clock;
  term_->PrepareResiduals(*k_, evaluate_jacobians);
  prepared_ = *k_;
  have_jacobians_ = evaluate_jacobians;
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
