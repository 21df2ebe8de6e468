// The unknowns of a frame's problem, as the solvers see them: one displacement k_s along the
// input surface's normal per surface Gaussian, each held within [-bound, bound]
// (EnergyOptions::k_max). The solvers read the number of unknowns and their bounds from here, not
// from the energy's options, so that a problem of other unknowns states them in one place.
#ifndef FINECAP_ENERGY_PARAMETER_LAYOUT_H_
#define FINECAP_ENERGY_PARAMETER_LAYOUT_H_

namespace finecap {

struct ParameterLayout {
  int num_unknowns = 0;
  double bound = 0.0;  // |k_s| <= bound, metres.
};

}  // namespace finecap

#endif  // FINECAP_ENERGY_PARAMETER_LAYOUT_H_
