// The energy's options (energy_options.h): the declaration of their fields (option_fields.h), their
// Check() and the names of their choices (enum_names.h); pure validation, apart from the energy's
// code.
#include "finecap/energy/energy_options.h"

namespace finecap {

const std::vector<EnumName<SimilarityType>>& EnumNames(SimilarityType) {
  static const std::vector<EnumName<SimilarityType>> names = {
      {SimilarityType::kPaper, "paper"},
      {SimilarityType::kSurfaceColor, "surface_color"},
      {SimilarityType::kConsensus, "consensus"}};
  return names;
}

const std::vector<EnumName<RegUnit>>& EnumNames(RegUnit) {
  static const std::vector<EnumName<RegUnit>> names = {{RegUnit::kMillimetres, "mm"},
                                                       {RegUnit::kMetres, "m"}};
  return names;
}

const std::vector<EnumName<SurfacePatches>>& EnumNames(SurfacePatches) {
  static const std::vector<EnumName<SurfacePatches>> names = {
      {SurfacePatches::kFaceCover, "face_cover"}, {SurfacePatches::kAll, "all"}};
  return names;
}

const OptionFields<EnergyOptions>& EnergyOptions::Fields() {
  static const OptionFields<EnergyOptions> fields = [] {
    OptionFields<EnergyOptions> f;
    f.AddEnum("similarity", &EnergyOptions::similarity,
              "paper: the paper's E_sim as printed; surface_color: each surface Gaussian's colour "
              "against the image around its projection (peaks at the truth); consensus: the "
              "cameras that see a patch agree on its normalised colours (no reference colours).");
    f.AddSection("consensus", &EnergyOptions::consensus, ConsensusOptions::Fields());
    f.AddEnum("overlap", &EnergyOptions::overlap,
              "Overlap of two Gaussians: the paper's printed form, the exact integral, or patch "
              "(image Gaussians as the squares they stand for).");
    f.AddDouble("color_cutoff", &EnergyOptions::color_cutoff,
                "Wendland cut-off D of the colour weight of the paper's E_sim (paper: 0.05).", 1e-6,
                10.0);
    f.AddDouble("reach_sigmas", &EnergyOptions::reach_sigmas,
                "Pairs of Gaussians are evaluated up to this many combined sigmas apart.", 0.5,
                10.0);
    f.AddDouble("k_max", &EnergyOptions::k_max,
                "Bound on the displacement along the normal, m; a frame whose plane sweep finds "
                "it limiting doubles it (refine.sweep.widen_share).",
                1e-5, kLargestKMax);
    f.AddDouble("w_reg", &EnergyOptions::w_reg, "Weight of the regulariser (paper: 1).", 0.0, 1e12);
    f.AddDouble("w_prior", &EnergyOptions::w_prior,
                "Weight of a pull of k towards the input surface (not in the paper); keeps "
                "textureless regions in place.",
                0.0, 1e12);
    f.AddDouble("confidence_prior", &EnergyOptions::confidence_prior,
                "Strength of a pull of k towards the input surface where the images cannot decide "
                "it (few cameras, steep views, wide plain regions), in units of the median data "
                "curvature (not in the paper; 0: off).",
                0.0, 1e6);
    f.AddGroup(&EnergyOptions::terms, TermOptions::Fields());
    f.AddDouble("confidence_threshold", &EnergyOptions::confidence_threshold,
                "Colour variation, as a fraction of its median, below which the cloth counts as "
                "plain.",
                1e-9, 1e3);
    f.AddInt("confidence_opening", &EnergyOptions::confidence_opening,
             "Passes of the opening of the plain region: narrower plain patches are left to the "
             "regulariser.",
             0, 20);
    f.AddInt("reg_rings", &EnergyOptions::reg_rings,
             "Regulariser neighbourhood Delta in edges, also its Wendland cut-off (paper: 2).", 1,
             10);
    f.AddEnum("reg_unit", &EnergyOptions::reg_unit,
              "Unit of k inside E_reg (the paper's lengths are millimetres).");
    return f;
  }();
  return fields;
}

const OptionFields<ConsensusOptions>& ConsensusOptions::Fields() {
  static const OptionFields<ConsensusOptions> fields = [] {
    OptionFields<ConsensusOptions> f;
    f.AddDouble("contrast_floor", &ConsensusOptions::contrast_floor,
                "Consensus similarity: patches with less contrast than this (colour units) are "
                "not normalised to unit variance.",
                1e-6, 1.0);
    f.AddInt("min_cameras", &ConsensusOptions::min_cameras,
             "Consensus similarity: cameras that must see a whole patch for it to count.", 2, 64);
    f.AddInt("passes", &ConsensusOptions::passes,
             "Consensus similarity: solves per frame, each later one with patches shaped like the "
             "surface the one before found.",
             1, 10);
    f.AddInt("shape_smoothing_rounds", &ConsensusOptions::shape_smoothing_rounds,
             "Consensus similarity: rounds of averaging over mesh neighbours of the surface a pass "
             "found before it shapes the next pass's patches (0: as found), counted on the input "
             "subdivided once (four times as many per further level: the same reach).",
             0, 100);
    f.AddInt("patch_rings", &ConsensusOptions::patch_rings,
             "Consensus similarity: a patch is a surface Gaussian and its neighbours up to this "
             "many edges of the input subdivided once away (patch_rings x "
             "2^(model.subdivision_levels - 1) edges of the refined mesh, at most 4).",
             1, kMaxPatchRings);
    f.AddBool("gain_per_channel", &ConsensusOptions::gain_per_channel,
              "Consensus similarity: normalise each camera's gain per channel (white balance) "
              "instead of once for all channels (exposure).");
    f.AddDouble("robust_fraction", &ConsensusOptions::robust_fraction,
                "Consensus similarity: scale of Cauchy's loss on each patch's disagreement, as a "
                "fraction of that of unrelated patches; 0: plain least squares.",
                0.0, 100.0);
    f.AddDouble("sample_spacing", &ConsensusOptions::sample_spacing,
                "Consensus similarity: 0 reads a patch's colours at its surface Gaussians; above 0 "
                "at samples of the surface this many pixel footprints apart, at the images' own "
                "resolution.",
                0.0, 16.0);
    f.AddDouble("sample_blur", &ConsensusOptions::sample_blur,
                "Consensus similarity with samples: standard deviation (pixels) of the blur of the "
                "images the samples read.",
                0.0, 8.0);
    f.AddDouble("view_cosine_power", &ConsensusOptions::view_cosine_power,
                "Consensus similarity: a camera's squared residuals in a patch count the cosine of "
                "its view angle at the surface to this power, relative to the patch's other "
                "cameras (0: every camera alike).",
                0.0, 8.0);
    f.AddDouble("surface_weight", &ConsensusOptions::surface_weight,
                "Consensus similarity with samples: weight of a second term that compares the "
                "refined mesh itself, each sample moved with the corners of its face, beside the "
                "patches moved as wholes, in the detail stage's last pass; 0: the patches alone "
                "(every capture measured loses detail, at 0.8-0.9 times a frame's time).",
                0.0, 100.0);
    f.AddEnum("surface_patches", &ConsensusOptions::surface_patches,
              "Consensus similarity with samples: the patches through which the second term "
              "compares the refined mesh. face_cover: those of a set of vertices with a corner on "
              "every face, about a third of them, so that each face is compared once; all: every "
              "patch, so that each face is compared in the patches of its three corners.");
    f.AddBool("shared_appearance", &ConsensusOptions::shared_appearance,
              "Consensus similarity with samples: compare each patch also with the colours the "
              "frame before's refined surface showed at its samples (the appearance shared by "
              "the frames), as one more view.");
    return f;
  }();
  return fields;
}

void EnergyOptions::Check() const {
  Fields().CheckValues(*this, "EnergyOptions::");
  consensus.Check();
  terms.Check();
}

void ConsensusOptions::Check() const { Fields().CheckValues(*this, "ConsensusOptions::"); }

}  // namespace finecap
