// The Check() of the options structs of refinement (refine.h, the colour options of sequence.h) and
// the names of their choices (enum_names.h): pure validation, kept apart from the stages' code so
// that reading a config links none of the stages.
//
// Each Check() names the C++ field it refuses; its ranges are the config schema's
// (config_options_test walks the schema and holds them to it).
#include "finecap/energy/energy_options.h"
#include "finecap/model/gaussian_overlap.h"
#include "finecap/refine/refine.h"
#include "finecap/refine/sequence.h"
#include "finecap/solvers/solver.h"
#include "finecap/solvers/sweep.h"
#include "finecap/util/error.h"
#include "util/option_checks.h"

namespace finecap {

using internal::RequireFieldRange;
using internal::RequireKnownChoice;

const std::vector<EnumName<ReferenceColorSource>>& EnumNames(ReferenceColorSource) {
  static const std::vector<EnumName<ReferenceColorSource>> names = {
      {ReferenceColorSource::kPixels, "pixels"},
      {ReferenceColorSource::kImageModel, "image_model"}};
  return names;
}

const std::vector<EnumName<ReferenceSurface>>& EnumNames(ReferenceSurface) {
  static const std::vector<EnumName<ReferenceSurface>> names = {
      {ReferenceSurface::kCoarse, "coarse"}, {ReferenceSurface::kRefined, "refined"}};
  return names;
}

void ReferenceColorOptions::Check() const {
  internal::RequireKnownChoice(reference_surface, "ReferenceColorOptions::reference_surface");
  internal::RequireFieldRange(follow_colors, 0.0, 1.0, "ReferenceColorOptions::follow_colors");
  internal::RequireFieldRange(follow_anchor, 0.0, 1.0, "ReferenceColorOptions::follow_anchor");
}

void RefineOptions::Check() const {
  RequireFieldRange(subdivision_levels, 0, 4, "RefineOptions::subdivision_levels");
  RequireKnownChoice(subdivision, "RefineOptions::subdivision");
  RequireFieldRange(sigma_hat, 1e-5, 1.0, "RefineOptions::sigma_hat");
  RequireKnownChoice(reference_colors, "RefineOptions::reference_colors");
  image.Check();
  visibility.Check();
  energy.Check();
  solver.Check();
  sweep.Check();
  coarse_to_fine.Check();
}

void CoarseToFineOptions::Check() const {
  RequireFieldRange(levels, 1, 5, "CoarseToFineOptions::levels");
  RequireFieldRange(scale, 1.0001, 4.0, "CoarseToFineOptions::scale");
}

}  // namespace finecap
