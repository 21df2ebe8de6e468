// Options of the refinement energy E = E_sim - w_reg * E_reg (the paper's section 5).
#ifndef FINECAP_ENERGY_OPTIONS_H_
#define FINECAP_ENERGY_OPTIONS_H_

#include <string>
#include <vector>

#include "finecap/model/gaussian_overlap.h"
#include "finecap/util/enum_names.h"

namespace finecap {

// What the similarity E_sim measures (EnergyOptions::similarity).
enum class SimilarityType { kPaper, kSurfaceColor, kConsensus };
const std::vector<EnumName<SimilarityType>>& EnumNames(SimilarityType);

// The unit in which k enters E_reg (EnergyOptions::reg_unit).
enum class RegUnit { kMillimetres, kMetres };
const std::vector<EnumName<RegUnit>>& EnumNames(RegUnit);

// Options of the consensus similarity (consensus_similarity.h).
struct ConsensusOptions {
  // epsilon of the per-camera normalisation, in colour units: patches whose contrast is below it
  // are not stretched to unit variance, so image noise on plain cloth is not amplified.
  // Default 0.005 (about 1.3 grey levels of 255).
  double contrast_floor = 0.005;
  // Cameras that must see a whole patch for it to count. At least 2. Default 2.
  int min_cameras = 2;
  // Solves per frame: after the first, each patch moves as a piece of the surface the previous
  // solve found instead of the input surface (ConsensusSimilarity::SetPatchShape), so that
  // folds steeper than the input no longer bias the windows towards it. Default 2.
  int passes = 2;
  // Rounds of averaging over mesh neighbours (Regularizer::AverageOverNeighbours) of the
  // displacement a solve found before it shapes the next pass's patches. A patch compares a
  // window of about seven Gaussians, so what the images determine is the window's displacement;
  // a member's own difference from its neighbours is mostly the solve's noise, and shaping the
  // window after that noise adds it to the next pass (synth_skirt_ramp's flat frame 0: 0.48 mm
  // after one pass, 0.64 mm after a second shaped by the raw displacement, 0.54 mm after one
  // shaped by its one-ring average; folds keep their shape, being longer than a patch).
  // 0: the displacement as found. Default 1.
  int shape_smoothing_rounds = 1;
  static constexpr int kMaxPatchRings = 4;

  // Size of a patch: a surface Gaussian and its neighbours up to this many mesh edges away, in
  // [1, kMaxPatchRings]. A refinement counts them in edges of its input subdivided once
  // (PatchRingsAt in refine.h). Default 1.
  int patch_rings = 1;
  // Whether each camera's gain is normalised per channel (white balance) or once for all three
  // (exposure; its offsets stay per channel). Default true.
  bool gain_per_channel = true;
  // Cauchy's robust loss on each patch's squared disagreement, with its scale this fraction of
  // the disagreement of unrelated patches; 0 turns it off (plain least squares).
  double robust_fraction = 0.5;
  // Where the colours of a patch are read. 0: at its surface Gaussians only, one per vertex,
  // blurred by sigma_hat (ConsensusSimilarity). Above 0: then a second solve, from the surface
  // the surface Gaussians found, reads them at samples of the refined surface about this many
  // pixel footprints apart (the faces split linearly until their edges are that short), at the
  // images' own resolution (PixelConsensusSimilarity): detail between the vertices, which the
  // Gaussians blur away, steers each vertex. Default 1.
  double sample_spacing = 1.0;
  // With samples: the standard deviation, in pixels, of the Gaussian the images are blurred by
  // before the samples read them by bilinear interpolation. Default 0.4.
  double sample_blur = 0.4;

  void Check() const;
};

struct EnergyOptions {
  // Which similarity E_sim measures:
  //  kPaper:         the paper's E_sim as printed, with the min() clamp per image Gaussian;
  //  kSurfaceColor:  each surface Gaussian's colour against the image colour around its
  //                   projection, the overlap-weighted mean of the image Gaussians' colours (a
  //                   closed-form least-squares residual per surface Gaussian and camera; see
  //                   docs/method.md for why it peaks at the true surface, the paper's not);
  //  kConsensus:     the cameras that see a patch of surface Gaussians must agree on its
  //                   normalised colours; no reference colours (consensus_similarity.h).
  // Default kConsensus: on captures whose reference frame is as coarse as any other (every real
  // one) it recovers detail where surface_color, whose reference colours then belong to the
  // wrong surface points, does not (measured with `finecap probe` and `finecap refine`, see
  // docs/method.md; configs/surface_color.yaml keeps surface_color's settings).
  SimilarityType similarity = SimilarityType::kConsensus;
  // Closed form of the overlap of two Gaussians: kPrinted (the paper's equation), kExact (the
  // true integral, half the exponent) or kPatch. See gaussian_overlap.h.
  OverlapForm overlap = OverlapForm::kPrinted;
  // Cut-off D of the Wendland colour weight T(|eta_i - eta_s|) of the paper's E_sim, in colour
  // distance units (color.h). Paper: 0.05.
  double color_cutoff = 0.05;
  // A pair of Gaussians is evaluated when their means are less than this many combined standard
  // deviations sqrt(sigma_s^2 + sigma_i^2) apart for some allowed k. Default 3.
  double reach_sigmas = 3.0;
  // Bound on the displacement |k| along the normal, metres. Default 0.02; a refinement makes it
  // follow from the scene unless set (RefineOptions::scene_lengths).
  double k_max = 0.02;
  // Weight w_reg of the regulariser. Paper: 1 (with k in millimetres inside E_reg, and its
  // E_sim). Default 1e-6, for the consensus similarity, whose residuals are contrast-weighted
  // normalised patches (~0.01-0.1); surface_color was measured with 1e-7, and the paper's E_sim,
  // which counts image patches (~1e4), with 1.
  double w_reg = 1e-6;
  // Weight w_prior of a pull of every k_s towards 0 (the input surface), E_prior = sum (u k_s)^2,
  // E = E_sim - w_reg E_reg - w_prior E_prior. Where the images say nothing about k (a plain,
  // textureless cloth) it keeps the input; where they do, the data outweighs it. Not in the
  // paper. Default 0.
  double w_prior = 0.0;
  // Strength mu of a pull towards the input surface where the images cannot decide k, in units
  // of the median data curvature (input_prior.h): where too few cameras see a Gaussian, or only
  // at steep angles, or the cloth around it is plain. Not in the paper. 0 turns it off. Default
  // 1: on a sparse rig it keeps the surface that the cameras cannot see well where it was
  // (docs/measurements.md, 2026-12-05); where they see it well it holds nothing. surface_color
  // needs 300 (configs/surface_color.yaml): its single colours carry nothing on plain cloth.
  double confidence_prior = 1.0;
  // Strength of a pull of each k towards the solved k of the frame before (temporal coherence),
  // in units of the median data curvature, as confidence_prior. The frame before's displacement
  // along its normal is carried to this frame by the input's own motion: the same k on this
  // frame's surface. Read from the saved files of that frame (as refine.warm_start is), so that
  // a resumed run pulls its first frame as an uninterrupted run does; the first frame of a
  // capture, or one whose predecessor is not done (a shard run beside the one before it), is not
  // pulled. Not in the paper. 0 turns it off. 0.3 lowers both the error and the flicker of a
  // noisy capture and holds the other synthetic captures within a few tenths of a point
  // (docs/measurements.md, 2026-12-05). Default 0: with the pull a sequence is one chain, so
  // shards run side by side (a Slurm array) would no longer equal one process at their first
  // frames; a single process or shards run in turn get the same result with it.
  double temporal_weight = 0.0;
  // The consensus similarity's options.
  ConsensusOptions consensus;
  // Colour variation, as a fraction of its median, below which the cloth counts as plain (the
  // plainness is exp(-V / (threshold * median V))). Default 0.05.
  double confidence_threshold = 0.05;
  // Passes of the morphological opening of the plain region, each over the regulariser
  // neighbourhood (reg_rings edges): plain patches narrower than about 2 * opening * reg_rings
  // edges are left to the regulariser. Default 3.
  int confidence_opening = 3;
  // Neighbourhood size Delta of the regulariser, edges; also the Wendland cut-off of its weights
  // T(delta_sj). Paper: 2.
  int reg_rings = 2;
  // Unit in which k enters E_reg: millimetres (the paper's lengths) or metres.
  RegUnit reg_unit = RegUnit::kMillimetres;

  // Metres to the unit of E_reg.
  double RegUnitScale() const { return reg_unit == RegUnit::kMillimetres ? 1000.0 : 1.0; }
  void Check() const;
};

}  // namespace finecap

#endif  // FINECAP_ENERGY_OPTIONS_H_
