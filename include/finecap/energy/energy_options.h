// Options of the refinement energy E = E_sim - w_reg * E_reg (the paper's section 5).
#ifndef FINECAP_ENERGY_OPTIONS_H_
#define FINECAP_ENERGY_OPTIONS_H_

#include <string>
#include <vector>

#include "finecap/energy/term_options.h"
#include "finecap/model/gaussian_overlap.h"
#include "finecap/util/enum_names.h"
#include "finecap/util/option_fields.h"

namespace finecap {

// What the similarity E_sim measures (EnergyOptions::similarity).
enum class SimilarityType { kPaper, kSurfaceColor, kConsensus };
const std::vector<EnumName<SimilarityType>>& EnumNames(SimilarityType);

// The unit in which k enters E_reg (EnergyOptions::reg_unit).
enum class RegUnit { kMillimetres, kMetres };
const std::vector<EnumName<RegUnit>>& EnumNames(RegUnit);

// Which patches the detail stage's second term compares the refined mesh through
// (ConsensusOptions::surface_patches).
enum class SurfacePatches { kFaceCover, kAll };
const std::vector<EnumName<SurfacePatches>>& EnumNames(SurfacePatches);

// Options of the consensus similarity (consensus_similarity.h). The fields are documented where
// Fields() declares them (docs/configuration.md: energy.consensus); the comments below add what
// the documentation does not say.
struct ConsensusOptions {
  // epsilon of the per-camera normalisation: image noise on plain cloth is not amplified. 0.005
  // is about 1.3 grey levels of 255.
  double contrast_floor = 0.005;
  int min_cameras = 2;
  // After the first solve, each patch moves as a piece of the surface the previous solve found
  // instead of the input surface (ConsensusSimilarity::SetPatchShape), so that folds steeper than
  // the input no longer bias the windows towards it.
  int passes = 2;
  // Regularizer::AverageOverNeighbours. A patch compares a window of about seven Gaussians, so
  // what the images determine is the window's displacement; a member's own difference from its
  // neighbours is mostly the solve's noise, and shaping the window after that noise adds it to
  // the next pass (synth_skirt_ramp's flat frame 0: 0.48 mm after one pass, 0.64 mm after a
  // second shaped by the raw displacement, 0.54 mm after one shaped by its one-ring average;
  // folds keep their shape, being longer than a patch).
  int shape_smoothing_rounds = 1;
  static constexpr int kMaxPatchRings = 4;

  // A refinement counts them in edges of its input subdivided once (PatchRingsAt in refine.h).
  int patch_rings = 1;
  // Per channel or not, a camera's offsets stay per channel.
  bool gain_per_channel = true;
  // The loss is on each patch's squared disagreement.
  double robust_fraction = 0.5;
  // 0: one colour per vertex, blurred by sigma_hat (ConsensusSimilarity). Above 0: a second
  // solve, from the surface the surface Gaussians found, reads the samples (each face split into
  // equal triangles, as many a side as bring the mean edge to this length or less;
  // PixelConsensusSimilarity): detail between the vertices, which the Gaussians blur away, steers
  // each vertex.
  double sample_spacing = 1.0;
  // The samples read the blurred images by bilinear interpolation.
  double sample_blur = 0.4;
  // A camera that sees a patch at a steep angle sees its texture foreshortened, fewer of its
  // pixels on it and its colours blurred across the tilt, and agrees less with the others at the
  // right depth; its squared residuals in the patch count cos^p of its view angle, relative to
  // the patch's other cameras (PatchAgreementTerm::AddPatch), in both stages. p = 1 gained on
  // every synthetic capture and camera count (docs/measurements.md, 2026-12-06 (night)); 0: every
  // camera alike.
  double view_cosine_power = 1.0;
  // With samples: the weight of the detail stage's second term, which compares the refined mesh
  // itself (each sample where the blend of its face's corners' k puts it;
  // SurfaceConsensusSimilarity), beside the patches moved as wholes, in the detail stage's last
  // pass; 0: the patches alone. 1 gains on every capture and camera count measured and makes
  // level 2 beat level 1 on both real captures, at 1.1-1.3 times a frame's time
  // (docs/measurements.md, 2026-12-06 (late night)).
  double surface_weight = 1.0;
  // Every face lies in the patches of its three corners; kFaceCover compares it in one of them
  // (SurfaceConsensusSimilarity).
  SurfacePatches surface_patches = SurfacePatches::kFaceCover;
  // The surface's appearance is the same in every frame while its shape changes: with it on, the
  // colours the frame before's refined surface showed at each sample (averaged over the cameras
  // that saw it; SurfaceSamples::appearance) are one more view every patch is compared with, so
  // that a patch two cameras see gets a third comparison. Read from the run folder, as the
  // temporal pull's frame before is.
  bool shared_appearance = false;

  static const OptionFields<ConsensusOptions>& Fields();  // option_fields.h
  void Check() const;
};

// The fields are documented where Fields() declares them (docs/configuration.md: energy); the
// comments below add what the documentation does not say.
struct EnergyOptions {
  //  kPaper:         with the min() clamp per image Gaussian;
  //  kSurfaceColor:  the image colour is the overlap-weighted mean of the image Gaussians' colours
  //                   (a closed-form least-squares residual per surface Gaussian and camera; see
  //                   docs/method.md for why it peaks at the true surface, the paper's not);
  //  kConsensus:     consensus_similarity.h.
  // kConsensus by default: on captures whose reference frame is as coarse as any other (every
  // real one) it recovers detail where surface_color, whose reference colours then belong to the
  // wrong surface points, does not (measured with `finecap probe` and `finecap refine`, see
  // docs/method.md; configs/surface_color.yaml keeps surface_color's settings).
  SimilarityType similarity = SimilarityType::kConsensus;
  OverlapForm overlap = OverlapForm::kPrinted;  // gaussian_overlap.h; kExact: half the exponent.
  // Of the weight T(|eta_i - eta_s|), in colour distance units (color.h).
  double color_cutoff = 0.05;
  // Combined: sqrt(sigma_s^2 + sigma_i^2), for some allowed k.
  double reach_sigmas = 3.0;
  // A refinement makes it follow from the scene unless set (RefineOptions::scene_lengths), and
  // widens it for a frame whose plane sweep finds it limiting (SweepOptions::widen_share).
  static constexpr double kLargestKMax = 1.0;
  double k_max = 0.02;
  // The paper's 1 is with k in millimetres inside E_reg, and its E_sim. 1e-6 for the consensus
  // similarity, whose residuals are contrast-weighted normalised patches (~0.01-0.1);
  // surface_color was measured with 1e-7, and the paper's E_sim, which counts image patches
  // (~1e4), with 1.
  double w_reg = 1e-6;
  // E_prior = sum (u k_s)^2, E = E_sim - w_reg E_reg - w_prior E_prior. Where the images say
  // nothing about k it keeps the input; where they do, the data outweighs it.
  double w_prior = 0.0;
  // Strength mu (input_prior.h). 1: on a sparse rig it keeps the surface that the cameras cannot
  // see well where it was (docs/measurements.md, 2026-12-05); where they see it well it holds
  // nothing. surface_color needs 300 (configs/surface_color.yaml): its single colours carry
  // nothing on plain cloth.
  double confidence_prior = 1.0;
  // The options of the terms that own a section of their own (term_options.h).
  TermOptions terms;
  ConsensusOptions consensus;
  // The plainness is exp(-V / (threshold * median V)).
  double confidence_threshold = 0.05;
  // Each pass over the regulariser neighbourhood (reg_rings edges): plain patches narrower than
  // about 2 * opening * reg_rings edges are left to the regulariser.
  int confidence_opening = 3;
  int reg_rings = 2;  // Also the Wendland cut-off of the weights T(delta_sj).
  RegUnit reg_unit = RegUnit::kMillimetres;

  // Metres to the unit of E_reg.
  double RegUnitScale() const { return reg_unit == RegUnit::kMillimetres ? 1000.0 : 1.0; }
  static const OptionFields<EnergyOptions>& Fields();  // option_fields.h
  void Check() const;
};

}  // namespace finecap

#endif  // FINECAP_ENERGY_OPTIONS_H_
