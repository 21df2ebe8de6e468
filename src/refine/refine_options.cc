// The options structs of refinement (refine.h, the colour options of sequence.h): the declaration
// of their fields (option_fields.h), their Check() and the names of their choices (enum_names.h);
// pure validation, kept apart from the stages' code so that reading a config links none of the
// stages.
#include "finecap/energy/energy_options.h"
#include "finecap/model/gaussian_overlap.h"
#include "finecap/refine/refine.h"
#include "finecap/refine/sequence.h"
#include "finecap/solvers/solver.h"
#include "finecap/solvers/sweep.h"
#include "finecap/util/error.h"

namespace finecap {

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

const OptionFields<ReferenceColorOptions>& ReferenceColorOptions::Fields() {
  static const OptionFields<ReferenceColorOptions> fields = [] {
    OptionFields<ReferenceColorOptions> f;
    f.AddEnum("reference_surface", &ReferenceColorOptions::reference_surface,
              "Where the reference frame colours the surface Gaussians (surface_color, paper): "
              "coarse (its input surface, the paper) or refined (that frame refined first with "
              "the default consensus similarity). No effect under consensus.");
    f.AddDouble("follow_colors", &ReferenceColorOptions::follow_colors,
                "Rate at which the colours follow the sequence, blended in from each refined "
                "frame not flagged worse; 0 = fixed at the reference frame (the paper). "
                "Sequential: not with runtime.shard. No effect under consensus.",
                0.0, 1.0);
    f.AddDouble("follow_anchor", &ReferenceColorOptions::follow_anchor,
                "Pull of the followed colours back towards the reference colours after each "
                "frame (against drift).",
                0.0, 1.0);
    return f;
  }();
  return fields;
}

void ReferenceColorOptions::Check() const {
  Fields().CheckValues(*this, "ReferenceColorOptions::");
}

const OptionFields<RefineOptions>& RefineOptions::ModelFields() {
  static const OptionFields<RefineOptions> fields = [] {
    OptionFields<RefineOptions> f;
    f.AddInt("subdivision_levels", &RefineOptions::subdivision_levels,
             "Subdivision levels applied to the coarse mesh before refinement.", 0, 4);
    f.AddEnum("subdivision", &RefineOptions::subdivision,
              "Scheme of that subdivision: loop (approximating: moves the input's vertices onto a "
              "smoother surface), butterfly (modified butterfly, interpolating: keeps them and "
              "places only the new vertices) or linear (the input's faces split, its surface "
              "unchanged).");
    f.AddDouble("sigma_hat", &RefineOptions::sigma_hat,
                "Standard deviation of every surface Gaussian, metres (paper: 0.007)", 1e-5, 1.0);
    f.AddEnum("reference_colors", &RefineOptions::reference_colors,
              "How the reference frame colours the surface Gaussians: pixels (the paper) or "
              "image_model (what the energy's image model shows in the best camera).");
    f.AddBool("bias_compensation", &RefineOptions::bias_compensation,
              "Add sigma_hat along the normal after solving (the paper's shrink compensation).");
    return f;
  }();
  return fields;
}

const OptionFields<RefineOptions>& RefineOptions::RunFields() {
  static const OptionFields<RefineOptions> fields = [] {
    OptionFields<RefineOptions> f;
    f.AddBool("keep_input_if_worse", &RefineOptions::keep_input_if_worse,
              "Write the input surface for a frame whose energy, or held-out NCC, got worse "
              "(always flagged).");
    f.AddBool("warm_start", &RefineOptions::warm_start,
              "Start each frame from the previous frame's displacement.");
    f.AddBool("views_follow_surface", &RefineOptions::views_follow_surface,
              "Find the detail stage's visibility, view angles and camera alignment again before "
              "each of its passes, at the surface the pass before found.");
    f.AddSection("coarse_to_fine", &RefineOptions::coarse_to_fine, CoarseToFineOptions::Fields());
    f.AddSection("sweep", &RefineOptions::sweep, SweepOptions::Fields());
    f.AddSection("camera_alignment", &RefineOptions::camera_alignment,
                 CameraAlignmentOptions::Fields());
    return f;
  }();
  return fields;
}

void RefineOptions::Check() const {
  ModelFields().CheckValues(*this, "RefineOptions::");
  RunFields().CheckValues(*this, "RefineOptions::");
  image.Check();
  visibility.Check();
  energy.Check();
  solver.Check();
  sweep.Check();
  coarse_to_fine.Check();
  camera_alignment.Check();
}

const OptionFields<CoarseToFineOptions>& CoarseToFineOptions::Fields() {
  static const OptionFields<CoarseToFineOptions> fields = [] {
    OptionFields<CoarseToFineOptions> f;
    f.AddInt("levels", &CoarseToFineOptions::levels,
             "Levels of a coarse-to-fine schedule per frame (wider Gaussians and a coarser image "
             "model first); 1: off.",
             1, 5);
    f.AddDouble("scale", &CoarseToFineOptions::scale,
                "Factor of sigma_hat and of the smallest quad-tree leaf from one level to the "
                "next coarser.",
                1.0001, 4.0);
    return f;
  }();
  return fields;
}

void CoarseToFineOptions::Check() const { Fields().CheckValues(*this, "CoarseToFineOptions::"); }

const OptionFields<CameraAlignmentOptions>& CameraAlignmentOptions::Fields() {
  static const OptionFields<CameraAlignmentOptions> fields = [] {
    OptionFields<CameraAlignmentOptions> f;
    f.AddInt("max_rounds", &CameraAlignmentOptions::max_rounds,
             "Detail stage: rounds at most of aligning each camera with the others (a shift of its "
             "principal point, per frame, that absorbs a calibration's error of a pixel or so); "
             "ends when no camera moves by 0.01 px any more. 0: the cameras as given.",
             0, 100);
    return f;
  }();
  return fields;
}

void CameraAlignmentOptions::Check() const {
  Fields().CheckValues(*this, "CameraAlignmentOptions::");
}

}  // namespace finecap
