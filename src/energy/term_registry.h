// The registry of the energy's terms: the one place that turns EnergyOptions into the terms of a
// frame's energy, and that knows which options each term reads. frame_energy.cc builds its
// similarity and its quadratic terms here, and similarity_needs.h's answers come from here, so
// that a new term is its folder (src/energy/terms/) and a few lines of this registry.
#ifndef FINECAP_ENERGY_TERM_REGISTRY_H_
#define FINECAP_ENERGY_TERM_REGISTRY_H_

#include <memory>
#include <vector>

#include "finecap/energy/energy_options.h"
#include "finecap/energy/frame_energy.h"
#include "finecap/energy/quadratic_term.h"
#include "finecap/energy/similarity.h"
#include "finecap/geometry/neighbourhood.h"

namespace finecap {
namespace internal {

// The similarity of options.similarity over `views` (their pair lists built) or, with `samples`
// (not empty), over the cameras' pixels at the samples.
std::unique_ptr<SimilarityTerm> MakeSimilarity(const SurfaceGaussians& surface,
                                               const std::vector<EnergyView>& views,
                                               const VertexNeighbourhoods& neighbourhoods,
                                               const SurfaceSamples& samples,
                                               const std::vector<CameraInput>& sample_cameras,
                                               const EnergyOptions& options);

// The quadratic terms the options ask for, in the order their pulls are gathered.
std::vector<std::unique_ptr<QuadraticTerm>> MakeQuadraticTerms(const TermContext& context);

// Whether the similarity weighs pairs of Gaussians by the agreement of their colours (the
// paper's), so that pair lists keep only pairs within EnergyOptions::color_cutoff.
bool WeighsPairsByColor(const EnergyOptions& options);

}  // namespace internal
}  // namespace finecap

#endif  // FINECAP_ENERGY_TERM_REGISTRY_H_
