// What the rest of finecap must know of the configured energy: how many cameras its similarity
// compares, whose colours its surface Gaussians carry, what its terms read and what its tables
// hold. The answers come from the registry of the energy's terms (src/energy/term_registry.cc),
// so that no code outside it tests a similarity's kind: a new term states its needs there.
#ifndef FINECAP_ENERGY_SIMILARITY_NEEDS_H_
#define FINECAP_ENERGY_SIMILARITY_NEEDS_H_

#include "finecap/energy/energy_options.h"

namespace finecap {

struct SimilarityNeeds {
  // Cameras that must see a surface Gaussian for it to take part: the consensus compares the
  // cameras of a frame with each other (ConsensusOptions::min_cameras); the others compare each
  // camera with the colours the surface carries, and one camera is enough.
  int cameras_per_gaussian = 1;
  // Whether a Gaussian that fewer than cameras_per_gaussian see within the view cap takes the
  // most frontal others up to VisibilityOptions::fallback_view_angle_deg.
  bool takes_fallback_views = false;
  // Whether the surface Gaussians carry each frame's own colours (taken as the reference frame's
  // are: for the plain-cloth measure and the sweep's fallback) rather than the reference frame's:
  // then no frame depends on another's surface, and the reference colours are neither taken at
  // a refined surface nor followed along the sequence.
  bool colors_of_each_frame = false;
  // Whether it compares patches of Gaussians, which average over a window and so want narrower
  // Gaussians than a similarity of single Gaussians (SceneLengthFactors).
  bool compares_patches = false;
  // Whether it reads the images at surface samples about a pixel apart after the image models'
  // stage (ConsensusOptions::sample_spacing above 0).
  bool reads_surface_samples = false;
  // Whether a term reads the displacement the frame before was solved with
  // (FrameEnergy::TakeFrameBefore), such as a temporal pull. A sequence then reads it from that
  // frame's saved files, as it does for a warm start.
  bool reads_frame_before = false;
};

// The needs of options.similarity under `options`.
SimilarityNeeds NeedsOf(const EnergyOptions& options);

// `options` with the paper's similarity as printed (eq. 6) in place of the configured one, every
// other setting kept: the one energy by which runs of different settings can be compared
// (run_comparison.h).
EnergyOptions WithThePapersSimilarity(EnergyOptions options);

// Nodes of each colour table the similarity keeps per observation (a surface Gaussian seen by a
// camera) for Gaussians of `sigma_hat` over [-k_max, k_max]; 0 for a similarity without tables.
int ColorTableNodes(const EnergyOptions& options, double sigma_hat);

}  // namespace finecap

#endif  // FINECAP_ENERGY_SIMILARITY_NEEDS_H_
