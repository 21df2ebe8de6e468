// The paper's conditioned gradient ascent (Robertini et al. 2014, section 5.3).
#include <cmath>

#include "solvers/solvers_internal.h"

namespace finecap {
namespace internal {

void SolveWithGradientAscent(const FrameEnergy& energy, const SolverOptions& options,
                             Eigen::VectorXd* k, SolverSummary* summary) {
  const Stopwatch clock;
  const double k_max = energy.layout().bound;
  const int n = static_cast<int>(k->size());
  Eigen::VectorXd gradient, previous_gradient = Eigen::VectorXd::Zero(n);
  // The conditioner: one step factor per k_s, scaled at the first iteration so that the largest
  // derivative moves its k_s by initial_step (the energy's scale does not matter).
  Eigen::VectorXd factor;
  double energy_value = energy.Evaluate(*k, &gradient);
  summary->evaluations = 1;
  summary->trace.push_back({0, energy_value, clock.Seconds()});
  summary->termination = "max_iterations";
  // On a non-smooth energy (the paper's min() clamp) a step can go downhill and the ascent end
  // below where it has been: the best iterate is returned.
  Eigen::VectorXd best_k = *k;
  double best_energy = energy_value;
  for (int iteration = 1; iteration <= options.max_iterations; ++iteration) {
    if (factor.size() == 0) {
      const double largest = gradient.cwiseAbs().maxCoeff();
      if (!(largest > 0.0)) {
        summary->termination = "zero_gradient";
        break;
      }
      factor = Eigen::VectorXd::Constant(n, options.initial_step / largest);
    }
    for (int s = 0; s < n; ++s) {
      const double agreement = gradient[s] * previous_gradient[s];
      if (agreement > 0.0) factor[s] *= options.step_growth;
      if (agreement < 0.0) factor[s] *= options.step_shrink;
      const double step = std::clamp(factor[s] * gradient[s], -options.max_step, options.max_step);
      (*k)[s] = std::clamp((*k)[s] + step, -k_max, k_max);
    }
    previous_gradient = gradient;
    const double previous_energy = energy_value;
    energy_value = energy.Evaluate(*k, &gradient);
    ++summary->evaluations;
    summary->iterations = iteration;
    summary->trace.push_back({iteration, energy_value, clock.Seconds()});
    if (energy_value > best_energy) {
      best_energy = energy_value;
      best_k = *k;
    }
    const double change = std::abs(energy_value - previous_energy);
    if (change <= options.function_tolerance * std::max(std::abs(previous_energy), 1e-300)) {
      summary->termination = "function_tolerance";
      break;
    }
  }
  if (energy_value < best_energy) {
    *k = best_k;
    summary->termination += ", best iterate returned";
  }
  summary->seconds = clock.Seconds();
  summary->seconds_evaluation = summary->seconds;
}

}  // namespace internal
}  // namespace finecap
