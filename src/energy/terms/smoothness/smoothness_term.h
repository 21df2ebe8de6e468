// The paper's smoothness term as a quadratic term of the energy (quadratic_term.h): w_reg E_reg
// (regularizer.h) as one difference per pair of neighbours, of root 2 sqrt(w_reg T(delta)) u, so
// that 1/2 sum root^2 (k_a - k_b)^2 = w_reg E_reg. None when w_reg is 0.
#ifndef FINECAP_ENERGY_TERMS_SMOOTHNESS_SMOOTHNESS_TERM_H_
#define FINECAP_ENERGY_TERMS_SMOOTHNESS_SMOOTHNESS_TERM_H_

#include <vector>

#include <Eigen/Core>

#include "finecap/energy/quadratic_term.h"
#include "finecap/energy/regularizer.h"

namespace finecap {

class SmoothnessTerm : public QuadraticTerm {
 public:
  // Reads the context's neighbours, which must outlive the term.
  explicit SmoothnessTerm(const TermContext& context);
  void AddDifferences(std::vector<Difference>* differences) const override;
  double DifferenceEnergy(const Eigen::VectorXd& k, Eigen::VectorXd* gradient) const override;

 private:
  const Regularizer& regularizer_;
  double w_reg_;
};

}  // namespace finecap

#endif  // FINECAP_ENERGY_TERMS_SMOOTHNESS_SMOOTHNESS_TERM_H_
