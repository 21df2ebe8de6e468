// Temporal coherence, not in the paper (its journal version smooths over time): each k_s pulled
// towards the displacement the frame before was solved with, carried along this frame's normal,
//
//   E_temporal = 1/2 sum_s mu H (k_s - k_s^before)^2,
//
// with mu = TemporalOptions::weight (energy.temporal.weight) and H the median data curvature at the
// input (TermContext::typical_data_curvature), so that mu is in the data's own units as the
// confidence pull's is. Folds of cloth move a little from frame to frame while the images' noise
// does not follow them: the pull holds what the frames agree on and damps the flicker. Nothing
// before the frame before is solved (TakeFrameBefore), and nothing on the first frame.
#ifndef FINECAP_ENERGY_TERMS_TEMPORAL_TEMPORAL_TERM_H_
#define FINECAP_ENERGY_TERMS_TEMPORAL_TEMPORAL_TERM_H_

#include <functional>

#include <Eigen/Core>

#include "finecap/energy/quadratic_term.h"
#include "finecap/energy/terms/temporal/temporal_options.h"

namespace finecap {

class TemporalTerm : public QuadraticTerm {
 public:
  TemporalTerm(const TermContext& context, const TemporalOptions& options);
  void AddPulls(Pulls* pulls) const override;
  bool TakeFrameBefore(const Eigen::VectorXd& k_before) override;

 private:
  double weight_;
  std::function<double()> typical_data_curvature_;
  Eigen::VectorXd target_;  // Empty until the frame before is known.
};

}  // namespace finecap

#endif  // FINECAP_ENERGY_TERMS_TEMPORAL_TEMPORAL_TERM_H_
