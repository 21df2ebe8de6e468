// The procedural folds: sums of periodic waves in the cloth's material coordinates.
#include <algorithm>
#include <cmath>

#include "synth/synth_internal.h"

namespace finecap {
namespace synth_internal {
namespace {

double Radians(double degrees) { return degrees * M_PI / 180.0; }

// Zero-mean cross-section of one wave period (phase in radians), peak-normalised for kSine.
double Profile(FoldProfile profile, double phase) {
  if (profile == FoldProfile::kRidge) return 4.0 / M_PI - 2.0 * std::abs(std::sin(0.5 * phase));
  return std::sin(phase);
}

// 0 at frame 0, 1 from `ramp_frames` on, smooth (zero slope) at both ends.
double Ramp(int frame, int ramp_frames) {
  if (ramp_frames <= 0) return 1.0;
  const double x = std::min(1.0, static_cast<double>(frame) / ramp_frames);
  return x * x * (3.0 - 2.0 * x);
}

}  // namespace

Eigen::VectorXd FoldDisplacement(const std::vector<FoldComponent>& folds, int ramp_frames,
                                 double mean_radius, const MaterialCoordinates& at, int frame) {
  Eigen::VectorXd displacement = Eigen::VectorXd::Zero(at.theta.size());
  const double ramp = Ramp(frame, ramp_frames);
  for (const FoldComponent& fold : folds) {
    const double orientation = Radians(fold.orientation);
    // Whole waves around the subject, so the folds close up seamlessly at theta = 2 pi.
    const double waves_around =
        std::round(2.0 * M_PI * mean_radius * std::cos(orientation) / fold.wavelength);
    const double down_frequency = 2.0 * M_PI * std::sin(orientation) / fold.wavelength;
    const double offset = Radians(fold.phase + fold.drift * frame);
    for (int i = 0; i < displacement.size(); ++i) {
      const double phase = waves_around * at.theta(i) + down_frequency * at.down(i) + offset;
      displacement(i) += fold.amplitude * Profile(fold.profile, phase);
    }
  }
  return ramp * displacement;
}

}  // namespace synth_internal
}  // namespace finecap
