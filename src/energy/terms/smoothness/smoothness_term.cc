#include "energy/terms/smoothness/smoothness_term.h"

#include <cmath>

namespace finecap {

SmoothnessTerm::SmoothnessTerm(const TermContext& context)
    : regularizer_(context.neighbours), w_reg_(context.options.w_reg) {}

void SmoothnessTerm::AddDifferences(std::vector<Difference>* differences) const {
  if (w_reg_ == 0.0) return;
  for (const Regularizer::Pair& pair : regularizer_.pairs()) {
    differences->push_back(
        {pair.a, pair.b, 2.0 * std::sqrt(w_reg_ * pair.weight) * regularizer_.unit_scale()});
  }
}

double SmoothnessTerm::DifferenceEnergy(const Eigen::VectorXd& k, Eigen::VectorXd* gradient) const {
  Eigen::VectorXd own_gradient;
  const double energy = regularizer_.Evaluate(k, gradient != nullptr ? &own_gradient : nullptr);
  if (gradient != nullptr) *gradient += w_reg_ * own_gradient;
  return w_reg_ * energy;
}

}  // namespace finecap
