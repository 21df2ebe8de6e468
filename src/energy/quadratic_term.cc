#include "finecap/energy/quadratic_term.h"

#include <cmath>

#include "finecap/util/error.h"

namespace finecap {

void Pulls::Add(const Eigen::VectorXd& curvature, const Eigen::VectorXd& target) {
  Require(curvature.size() == target.size(), "Pulls::Add", "one curvature per target expected");
  if (curvature_.size() == 0) {
    curvature_ = Eigen::VectorXd::Zero(target.size());
    target_ = Eigen::VectorXd::Zero(target.size());
  }
  Require(target.size() == target_.size(), "Pulls::Add", "one target per unknown expected");
  for (Eigen::Index s = 0; s < target.size(); ++s) {
    const double p = curvature[s];
    if (!(p > 0.0) || !std::isfinite(target[s])) continue;
    if (curvature_[s] == 0.0) {
      curvature_[s] = p;
      target_[s] = target[s];
      continue;
    }
    const double sum = curvature_[s] + p;
    target_[s] = (curvature_[s] * target_[s] + p * target[s]) / sum;
    curvature_[s] = sum;
  }
}

void Pulls::Add(double curvature, const Eigen::VectorXd& target) {
  Add(Eigen::VectorXd::Constant(target.size(), curvature), target);
}

double Pulls::Evaluate(const Eigen::VectorXd& k) const {
  const Eigen::VectorXd from_target = k - target_;
  return 0.5 * from_target.dot(curvature_.cwiseProduct(from_target));
}

}  // namespace finecap
