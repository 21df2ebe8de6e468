// The Check() of the energy's options (energy_options.h) and the names of its choices
// (enum_names.h): pure validation, apart from the energy's code. Each Check() names the C++ field
// it refuses; its ranges are the config schema's (config_options_test walks the schema and holds
// them to it).
#include "finecap/energy/energy_options.h"
#include "finecap/util/error.h"
#include "util/option_checks.h"

namespace finecap {

using internal::RequireFieldRange;
using internal::RequireKnownChoice;

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

void EnergyOptions::Check() const {
  RequireKnownChoice(similarity, "EnergyOptions::similarity");
  consensus.Check();
  RequireKnownChoice(overlap, "EnergyOptions::overlap");
  RequireFieldRange(color_cutoff, 1e-6, 10.0, "EnergyOptions::color_cutoff");
  RequireFieldRange(reach_sigmas, 0.5, 10.0, "EnergyOptions::reach_sigmas");
  RequireFieldRange(k_max, 1e-5, 1.0, "EnergyOptions::k_max");
  RequireFieldRange(w_reg, 0.0, 1e12, "EnergyOptions::w_reg");
  RequireFieldRange(w_prior, 0.0, 1e12, "EnergyOptions::w_prior");
  RequireFieldRange(confidence_prior, 0.0, 1e6, "EnergyOptions::confidence_prior");
  RequireFieldRange(temporal_weight, 0.0, 1e6, "EnergyOptions::temporal_weight");
  RequireFieldRange(confidence_threshold, 1e-9, 1e3, "EnergyOptions::confidence_threshold");
  RequireFieldRange(confidence_opening, 0, 20, "EnergyOptions::confidence_opening");
  RequireFieldRange(reg_rings, 1, 10, "EnergyOptions::reg_rings");
  RequireKnownChoice(reg_unit, "EnergyOptions::reg_unit");
}

void ConsensusOptions::Check() const {
  RequireFieldRange(contrast_floor, 1e-6, 1.0, "ConsensusOptions::contrast_floor");
  RequireFieldRange(min_cameras, 2, 64, "ConsensusOptions::min_cameras");
  RequireFieldRange(passes, 1, 10, "ConsensusOptions::passes");
  RequireFieldRange(shape_smoothing_rounds, 0, 100, "ConsensusOptions::shape_smoothing_rounds");
  RequireFieldRange(patch_rings, 1, kMaxPatchRings, "ConsensusOptions::patch_rings");
  RequireFieldRange(robust_fraction, 0.0, 100.0, "ConsensusOptions::robust_fraction");
  RequireFieldRange(sample_spacing, 0.0, 16.0, "ConsensusOptions::sample_spacing");
  RequireFieldRange(sample_blur, 0.0, 8.0, "ConsensusOptions::sample_blur");
}

}  // namespace finecap
