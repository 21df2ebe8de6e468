#include "energy/terms/temporal/temporal_term.h"

namespace finecap {

TemporalTerm::TemporalTerm(const TermContext& context, const TemporalOptions& options)
    : weight_(options.weight), typical_data_curvature_(context.typical_data_curvature) {}

void TemporalTerm::AddPulls(Pulls* pulls) const {
  if (target_.size() == 0) return;
  pulls->Add(weight_ * typical_data_curvature_(), target_);
}

bool TemporalTerm::TakeFrameBefore(const Eigen::VectorXd& k_before) {
  target_ = k_before;
  return true;
}

}  // namespace finecap
