#include "finecap/ceres_cost_functions.h"

#include "solvers/solvers_internal.h"

namespace finecap {

SharedEvaluationCallback::SharedEvaluationCallback(SimilarityTerm* term, const Eigen::VectorXd* k,
                                                   double* seconds)
    : term_(term), k_(k), seconds_(seconds) {}

void SharedEvaluationCallback::PrepareForEvaluation(bool evaluate_jacobians,
                                                    bool new_evaluation_point) {
  // A residual-only preparation cannot serve a later Jacobian request at the same point.
  if (!new_evaluation_point && (have_jacobians_ || !evaluate_jacobians)) return;
  const internal::Stopwatch clock;
  term_->PrepareResiduals(*k_, evaluate_jacobians);
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

RegularizerPairCost::RegularizerPairCost(double coefficient, bool fixed_neighbour)
    : coefficient_(coefficient) {
  set_num_residuals(1);
  mutable_parameter_block_sizes()->assign(fixed_neighbour ? 1 : 2, 1);
}

bool RegularizerPairCost::Evaluate(double const* const* parameters, double* residuals,
                                   double** jacobians) const {
  const bool pair = parameter_block_sizes().size() == 2;
  residuals[0] = coefficient_ * (parameters[0][0] - (pair ? parameters[1][0] : 0.0));
  if (jacobians == nullptr) return true;
  if (jacobians[0] != nullptr) jacobians[0][0] = coefficient_;
  if (pair && jacobians[1] != nullptr) jacobians[1][0] = -coefficient_;
  return true;
}

}  // namespace finecap
