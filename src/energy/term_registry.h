// The registry of the energy's terms: the one place that turns EnergyOptions into the terms of a
// frame's energy, and that knows which options each term reads. frame_energy.cc builds its
// data terms and its quadratic terms here, and similarity_needs.h's answers come from here, so
// that a new term is its folder (src/energy/terms/) and a few lines of this registry.
#ifndef FINECAP_ENERGY_TERM_REGISTRY_H_
#define FINECAP_ENERGY_TERM_REGISTRY_H_

#include <functional>
#include <memory>
#include <vector>

#include "finecap/energy/data_term.h"
#include "finecap/energy/energy_options.h"
#include "finecap/energy/frame_energy.h"
#include "finecap/energy/quadratic_term.h"
#include "finecap/geometry/neighbourhood.h"

namespace finecap {
namespace internal {

// What a data term may read of its frame as it is built; all of it outlives the terms.
struct DataTermContext {
  const SurfaceGaussians& surface;
  const std::vector<EnergyView>& views;  // Their pair lists built (none with samples).
  const VertexNeighbourhoods& neighbourhoods;
  const Regularizer& neighbours;  // What a term that smooths over the mesh reads.
  const SurfaceSamples& samples;  // Empty but for a term that reads the pixels at samples.
  const std::vector<CameraInput>& sample_cameras;
  const EnergyOptions& options;
};

// The data terms the options ask for, in the order they are summed.
struct DataTerms {
  // Summed from the first pass of the solver: the similarity of options.similarity over the
  // views or, with samples, over the cameras' pixels at the samples.
  std::vector<std::unique_ptr<DataTerm>> from_first_pass;
  // Summed from the last pass on (FrameEnergy::StartLastPass): the refined mesh read itself
  // (ConsensusOptions::surface_weight), which only the pass whose result is handed back needs.
  // Made when that pass starts, so that an energy whose last pass never comes (the detail stage
  // prepared anew for its next pass, RefineOptions::views_follow_surface) does not build them;
  // a maker reads the context's members and the first pass's terms, which outlive it.
  std::vector<std::function<std::unique_ptr<DataTerm>()>> from_last_pass;
};
DataTerms MakeDataTerms(const DataTermContext& context);

// The quadratic terms the options ask for, in the order their pulls are gathered.
std::vector<std::unique_ptr<QuadraticTerm>> MakeQuadraticTerms(const TermContext& context);

// Whether the similarity weighs pairs of Gaussians by the agreement of their colours (the
// paper's), so that pair lists keep only pairs within EnergyOptions::color_cutoff.
bool WeighsPairsByColor(const EnergyOptions& options);

}  // namespace internal
}  // namespace finecap

#endif  // FINECAP_ENERGY_TERM_REGISTRY_H_
