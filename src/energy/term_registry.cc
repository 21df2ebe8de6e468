#include "energy/term_registry.h"

#include "energy/terms/consensus/consensus_similarity.h"
#include "energy/terms/consensus/pixel_consensus_similarity.h"
#include "energy/terms/consensus/surface_consensus_similarity.h"
#include "energy/terms/paper/paper_similarity.h"
#include "energy/terms/prior/input_prior.h"
#include "energy/terms/smoothness/smoothness_term.h"
#include "energy/terms/surface_color/surface_color_similarity.h"
#include "energy/terms/temporal/temporal_term.h"
#include "finecap/energy/similarity_needs.h"
#include "finecap/util/error.h"

namespace finecap {
namespace internal {
namespace {

// For each surface Gaussian, the surface Gaussians at most `rings` edges away on the mesh (at most
// as far as the neighbourhoods reach).
std::vector<std::vector<int>> SurfaceRings(const SurfaceGaussians& surface,
                                           const VertexNeighbourhoods& neighbourhoods, int rings) {
  std::vector<int> surface_of_vertex(neighbourhoods.num_vertices(), -1);
  for (int s = 0; s < surface.size(); ++s) surface_of_vertex[surface.vertex_ids[s]] = s;
  std::vector<std::vector<int>> patches(surface.size());
  for (int s = 0; s < surface.size(); ++s) {
    const int v = surface.vertex_ids[s];
    for (int e = neighbourhoods.offsets[v]; e < neighbourhoods.offsets[v + 1]; ++e) {
      const int j = surface_of_vertex[neighbourhoods.neighbours[e]];
      if (neighbourhoods.edge_distances[e] <= rings && j >= 0) patches[s].push_back(j);
    }
  }
  return patches;
}

// The similarity of options.similarity.
std::unique_ptr<DataTerm> MakeSimilarity(const DataTermContext& context) {
  const EnergyOptions& options = context.options;
  const OverlapForm form = options.overlap;
  if (options.similarity == SimilarityType::kPaper)
    return std::make_unique<PaperSimilarity>(context.surface, context.views, form);
  if (options.similarity == SimilarityType::kConsensus) {
    auto term = std::make_unique<ConsensusSimilarity>(
        context.surface, context.views,
        SurfaceRings(context.surface, context.neighbourhoods, options.consensus.patch_rings), form,
        options.k_max, options.reach_sigmas, options.consensus);
    term->SmoothShapesOver(&context.neighbours);
    return term;
  }
  return std::make_unique<SurfaceColorSimilarity>(context.surface, context.views, form);
}

// The detail stage's terms, which read the surface samples: the patches moved as wholes and,
// with a weight, from the last pass on, the refined mesh itself read through the same patches.
// The earlier passes' results only shape the next pass's patches; the mesh that is handed back
// is the last pass's, and comparing it costs as much as the patches do.
DataTerms SampledTerms(const DataTermContext& context) {
  const ConsensusOptions& options = context.options.consensus;
  Require(context.options.similarity == SimilarityType::kConsensus, "energy.similarity",
          "surface samples (energy.consensus.sample_spacing) need the consensus similarity");
  auto patches =
      std::make_unique<PixelConsensusSimilarity>(context.samples, context.sample_cameras, options);
  patches->SmoothShapesOver(&context.neighbours);
  // The surface term reads through the patches; both live as long as the energy.
  const PixelConsensusSimilarity* read_through = patches.get();
  DataTerms terms;
  terms.from_first_pass.push_back(std::move(patches));
  if (options.surface_weight > 0.0) {
    const SurfaceSamples* samples = &context.samples;
    terms.from_last_pass.push_back([read_through, samples, &options] {
      return std::make_unique<SurfaceConsensusSimilarity>(*read_through, *samples, options);
    });
  }
  return terms;
}

}  // namespace

DataTerms MakeDataTerms(const DataTermContext& context) {
  if (context.samples.size() > 0) return SampledTerms(context);
  DataTerms terms;
  terms.from_first_pass.push_back(MakeSimilarity(context));
  return terms;
}

std::vector<std::unique_ptr<QuadraticTerm>> MakeQuadraticTerms(const TermContext& context) {
  std::vector<std::unique_ptr<QuadraticTerm>> terms;
  terms.push_back(std::make_unique<SmoothnessTerm>(context));
  terms.push_back(std::make_unique<InputPriorTerm>(context));
  if (context.options.terms.temporal.IsOn()) {
    terms.push_back(std::make_unique<TemporalTerm>(context, context.options.terms.temporal));
  }
  return terms;
}

bool WeighsPairsByColor(const EnergyOptions& options) {
  return options.similarity == SimilarityType::kPaper;
}

}  // namespace internal

const OptionFields<TermOptions>& TermOptions::Fields() {
  static const OptionFields<TermOptions> fields = [] {
    OptionFields<TermOptions> f;
    f.AddSection("temporal", &TermOptions::temporal, TemporalOptions::Fields());
    return f;
  }();
  return fields;
}

void TermOptions::Check() const { temporal.Check(); }

const std::vector<TermOptionSection>& TermOptionSections() {
  static const std::vector<TermOptionSection> sections = {
      {"TemporalOptions::", "energy.temporal.", TemporalOptions::Fields().Declared()}};
  return sections;
}

SimilarityNeeds NeedsOf(const EnergyOptions& options) {
  SimilarityNeeds needs;
  needs.reads_frame_before = options.terms.temporal.IsOn();
  if (options.similarity != SimilarityType::kConsensus) return needs;
  needs.cameras_per_gaussian = options.consensus.min_cameras;
  needs.takes_fallback_views = true;
  needs.colors_of_each_frame = true;
  needs.compares_patches = true;
  needs.reads_surface_samples = options.consensus.sample_spacing > 0.0;
  return needs;
}

EnergyOptions WithThePapersSimilarity(EnergyOptions options) {
  options.similarity = SimilarityType::kPaper;
  return options;
}

int ColorTableNodes(const EnergyOptions& options, double sigma_hat) {
  if (options.similarity != SimilarityType::kConsensus) return 0;
  return ConsensusSimilarity::NumTableNodes(sigma_hat, options.k_max);
}

}  // namespace finecap
