// The Ceres pieces of the least-squares form of the energy (solver.h), with hand-written
// Jacobians: one cost function per residual block of the similarity, one per pair of neighbours
// of the regulariser, and the evaluation callback that computes the similarity's residuals once
// per evaluation point for all blocks.
#ifndef FINECAP_CERES_COST_FUNCTIONS_H_
#define FINECAP_CERES_COST_FUNCTIONS_H_

#include <vector>

#include <ceres/cost_function.h>
#include <ceres/evaluation_callback.h>
#include <Eigen/Core>

#include "finecap/similarity.h"

namespace finecap {

// Calls SimilarityTerm::PrepareResiduals at every new evaluation point. `k` is the vector whose
// entries are the problem's parameter blocks: Ceres has written the point there when it calls.
// Time spent is added to *seconds.
class SharedEvaluationCallback : public ceres::EvaluationCallback {
 public:
  SharedEvaluationCallback(SimilarityTerm* term, const Eigen::VectorXd* k, double* seconds);
  void PrepareForEvaluation(bool evaluate_jacobians, bool new_evaluation_point) override;

 private:
  SimilarityTerm* term_;
  const Eigen::VectorXd* k_;
  double* seconds_;
  bool have_jacobians_ = false;
};

// Residual block `block` of the similarity, one 1-D parameter block per k_s it depends on. Its
// values are those of the last SharedEvaluationCallback preparation.
class SimilarityBlockCost : public ceres::CostFunction {
 public:
  SimilarityBlockCost(const SimilarityTerm& term, int block);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 protected:
  const SimilarityTerm& term_;
  int block_;
};

// The same residual block, but preparing the term itself at the parameters it is given (the
// other k_s held at `k`): slow, independent of any callback, for checking Jacobians with
// ceres::GradientChecker.
class IsolatedSimilarityBlockCost : public SimilarityBlockCost {
 public:
  IsolatedSimilarityBlockCost(SimilarityTerm* term, int block, const Eigen::VectorXd& k);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  SimilarityTerm* mutable_term_;
  Eigen::VectorXd k_;
};

// r = c (k_a - k_b), or r = c k_a when the neighbour is fixed at 0 (`fixed_neighbour`), with
// c = 2 sqrt(w_reg T(delta)) u, so that 1/2 sum r^2 = w_reg E_reg (regularizer.h).
class RegularizerPairCost : public ceres::CostFunction {
 public:
  RegularizerPairCost(double coefficient, bool fixed_neighbour);
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  double coefficient_;
};

}  // namespace finecap

#endif  // FINECAP_CERES_COST_FUNCTIONS_H_
