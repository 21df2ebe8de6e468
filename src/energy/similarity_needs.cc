#include "finecap/energy/similarity_needs.h"

#include "energy/consensus_similarity.h"

namespace finecap {

SimilarityNeeds NeedsOf(const EnergyOptions& options) {
  SimilarityNeeds needs;
  if (options.similarity != SimilarityType::kConsensus) return needs;
  needs.cameras_per_gaussian = options.consensus.min_cameras;
  needs.takes_fallback_views = true;
  needs.colors_of_each_frame = true;
  needs.compares_patches = true;
  needs.reads_surface_samples = options.consensus.sample_spacing > 0.0;
  return needs;
}

int ColorTableNodes(const EnergyOptions& options, double sigma_hat) {
  if (options.similarity != SimilarityType::kConsensus) return 0;
  return ConsensusSimilarity::NumTableNodes(sigma_hat, options.k_max);
}

}  // namespace finecap
