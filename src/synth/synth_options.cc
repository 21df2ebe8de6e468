// The synthetic capture's options (synth.h): the declaration of their fields (option_fields.h),
// their Check() and the names of their choices (enum_names.h); pure checks, apart from the
// generator's code.
#include <cmath>
#include <string>

#include "finecap/geometry/mesh_smoothing.h"
#include "finecap/synth/synth.h"
#include "finecap/util/error.h"
#include "util/option_checks.h"

namespace finecap {
namespace {

using internal::RequireFieldRange;

bool IsPowerOfTwo(int n) { return n > 0 && (n & (n - 1)) == 0; }

}  // namespace

const std::vector<EnumName<FoldProfile>>& EnumNames(FoldProfile) {
  static const std::vector<EnumName<FoldProfile>> names = {{FoldProfile::kSine, "sine"},
                                                           {FoldProfile::kRidge, "ridge"}};
  return names;
}

const std::vector<EnumName<TexturePattern>>& EnumNames(TexturePattern) {
  static const std::vector<EnumName<TexturePattern>> names = {{TexturePattern::kMixed, "mixed"},
                                                              {TexturePattern::kPlaid, "plaid"},
                                                              {TexturePattern::kStripes, "stripes"},
                                                              {TexturePattern::kPrint, "print"},
                                                              {TexturePattern::kNoise, "noise"}};
  return names;
}

const std::vector<EnumName<SynthSubject>>& EnumNames(SynthSubject) {
  static const std::vector<EnumName<SynthSubject>> names = {{SynthSubject::kSkirt, "skirt"},
                                                            {SynthSubject::kMesh, "mesh"}};
  return names;
}

const std::vector<EnumName<CoarseInput>>& EnumNames(CoarseInput) {
  static const std::vector<EnumName<CoarseInput>> names = {{CoarseInput::kUnfolded, "unfolded"},
                                                           {CoarseInput::kSmoothed, "smoothed"},
                                                           {CoarseInput::kExact, "exact"}};
  return names;
}

const std::vector<EnumName<SynthBackground>>& EnumNames(SynthBackground) {
  static const std::vector<EnumName<SynthBackground>> names = {
      {SynthBackground::kPlain, "plain"}, {SynthBackground::kPerCamera, "per_camera"}};
  return names;
}

const OptionFields<FoldComponent>& FoldComponent::Fields() {
  static const OptionFields<FoldComponent> fields = [] {
    OptionFields<FoldComponent> f;
    f.AddDouble("amplitude", &FoldComponent::amplitude, "Amplitude, m.", -0.1, 0.1);
    f.AddDouble("wavelength", &FoldComponent::wavelength, "Wavelength, m.", 0.01, 2.0);
    f.AddDouble("orientation", &FoldComponent::orientation,
                "Orientation, degrees (0 = crests run down).");
    f.AddDouble("phase", &FoldComponent::phase, "Phase, degrees.");
    f.AddDouble("drift", &FoldComponent::drift, "Drift of the phase, degrees per frame.");
    f.AddEnum("profile", &FoldComponent::profile, "Profile: sine or ridge.");
    return f;
  }();
  return fields;
}

void FoldComponent::Check(const std::string& where) const {
  Fields().CheckValues(*this, where + ".");
}

const OptionFields<SkirtOptions>& SkirtOptions::Fields() {
  static const OptionFields<SkirtOptions> fields = [] {
    OptionFields<SkirtOptions> f;
    f.AddDouble("waist_radius", &SkirtOptions::waist_radius,
                "Radius of the skirt at the waist (top), m.", 0.01, 5.0);
    f.AddDouble("hem_radius", &SkirtOptions::hem_radius,
                "Radius of the skirt at the hem (bottom), m; >= waist_radius.", 0.01, 5.0);
    f.AddDouble("length", &SkirtOptions::length, "Height from waist to hem, m.", 0.01, 10.0);
    f.AddDouble("flare_exponent", &SkirtOptions::flare_exponent,
                "Radius grows like s^p from waist (s = 0) to hem (s = 1); 1 is a cone.", 1.0, 10.0);
    f.AddDouble("waist_height", &SkirtOptions::waist_height,
                "Height of the waist above the floor (world y), m.");
    f.AddInt("around", &SkirtOptions::around, "Coarse mesh vertices around the tube.", 8, 100000);
    f.AddInt("down", &SkirtOptions::down, "Coarse mesh vertices from waist to hem.", 3, 100000);
    f.AddDouble("sway", &SkirtOptions::sway, "Peak sideways sway of the hem, m.", 0.0, 1.0);
    f.AddDouble("swing", &SkirtOptions::swing,
                "Peak twist of the hem about the vertical axis, degrees.", -90.0, 90.0);
    f.AddDouble("flare_wobble", &SkirtOptions::flare_wobble,
                "Peak relative difference of the hem outline's radii from round (fraction).", 0.0,
                0.5);
    f.AddDouble("period", &SkirtOptions::period, "Frames per cycle of the low-frequency motion.",
                1e-3, 1e9);
    return f;
  }();
  return fields;
}

void SkirtOptions::Check() const {
  Fields().CheckValues(*this, "SkirtOptions::");
  RequireFieldRange(hem_radius, waist_radius, Fields().Field("hem_radius").max,
                    "SkirtOptions::hem_radius");
}

const OptionFields<TextureOptions>& TextureOptions::Fields() {
  static const OptionFields<TextureOptions> fields = [] {
    OptionFields<TextureOptions> f;
    f.AddInt("width", &TextureOptions::width, "Texture width, texels (around).", 16, 16384);
    f.AddInt("height", &TextureOptions::height, "Texture height, texels (down).", 16, 16384);
    f.AddEnum("pattern", &TextureOptions::pattern,
              "Cloth print: plaid, motifs and noise mixed, or one of them alone.");
    f.AddDouble("textureless_begin", &TextureOptions::textureless_begin,
                "Start of the plain band, fraction of the height from the top.", 0.0, 1.0);
    f.AddDouble("textureless_end", &TextureOptions::textureless_end,
                "End of the plain band, fraction of the height (equal to begin: no band).", 0.0,
                1.0);
    f.AddCustom("textureless_color", "Colour of the plain band, RGB in [0, 1].", 0.0, 1.0);
    return f;
  }();
  return fields;
}

void TextureOptions::Check() const {
  const std::string where = "TextureOptions::";
  Fields().CheckValues(*this, where);
  RequireFieldRange(textureless_end, textureless_begin, Fields().Field("textureless_end").max,
                    where + "textureless_end");
  internal::CheckDeclaredNumbers(textureless_color.data(), 3, Fields().Field("textureless_color"),
                                 where + "textureless_color");
}

const OptionFields<RigOptions>& RigOptions::Fields() {
  static const OptionFields<RigOptions> fields = [] {
    OptionFields<RigOptions> f;
    f.AddInt("count", &RigOptions::count, "Cameras, evenly spaced on a ring around the subject.", 1,
             1000);
    f.AddInt("width", &RigOptions::width, "Image width, pixels.", 16, 20000);
    f.AddInt("height", &RigOptions::height, "Image height, pixels.", 16, 20000);
    f.AddDouble("focal", &RigOptions::focal, "Focal length, pixels.", 1.0, 1e6);
    f.AddDouble("distance", &RigOptions::distance,
                "Horizontal distance of the cameras from the subject's axis, m.", 0.05, 1e4);
    f.AddDoubleList("heights", &RigOptions::heights,
                    "Camera heights above the subject's centre, m; camera c uses entry c % size "
                    "(non-empty).");
    f.AddCustom("distortion",
                "Lens distortion (k1, k2, p1, p2, k3) of every camera, OpenCV's model.", -10.0,
                10.0);
    f.AddDouble("rotation_noise", &RigOptions::rotation_noise,
                "Calibration error: rotation standard deviation per axis, degrees.", 0.0, 10.0);
    f.AddDouble("translation_noise", &RigOptions::translation_noise,
                "Calibration error: centre offset standard deviation per axis, m.", 0.0, 1.0);
    f.AddDouble("focal_noise", &RigOptions::focal_noise,
                "Calibration error: relative focal length standard deviation.", 0.0, 0.5);
    return f;
  }();
  return fields;
}

void RigOptions::Check() const {
  const std::string where = "RigOptions::";
  Fields().CheckValues(*this, where);
  Require(!heights.empty(), where + "heights", "must list at least one height");
  internal::CheckDeclaredNumbers(distortion.data(), static_cast<int>(distortion.size()),
                                 Fields().Field("distortion"), where + "distortion");
}

RenderOptions SynthOptions::DefaultRenderOptions() {
  RenderOptions render;
  render.supersampling = 3;
  render.shade = true;
  // Bright enough that the sides turned away from the light keep their texture.
  render.ambient = 0.5;
  render.diffuse = 0.6;
  render.background = Eigen::Vector3d::Constant(0.12);
  return render;
}

const OptionFields<SynthOptions>& SynthOptions::Fields() {
  static const OptionFields<SynthOptions> fields = [] {
    OptionFields<SynthOptions> f;
    f.AddEnum("subject", &SynthOptions::subject,
              "skirt: the built-in flared tube (synth.skirt); mesh: the meshes at "
              "synth.mesh_path.");
    f.AddSection("skirt", &SynthOptions::skirt, SkirtOptions::Fields());
    f.AddString("mesh_path", &SynthOptions::mesh_path,
                "Subject \"mesh\": a mesh file or a folder of per-frame meshes of one topology "
                "(.ply, .obj, .off, .stl); world y up.");
    f.AddInt("num_frames", &SynthOptions::num_frames,
             "Frames to generate (at most the meshes in a mesh_path folder).", 1, 1000000);
    f.AddInt("truth_refinement", &SynthOptions::truth_refinement,
             "True surface edges per coarse edge (a power of two for subject \"mesh\").", 1, 16);
    f.AddCustom("folds",
                "Fold families, summed: amplitude m, wavelength m, orientation deg (0 = crests "
                "run down), phase deg, drift deg/frame, profile sine or ridge.");
    f.AddDouble("single_wavelength", &SynthOptions::single_wavelength,
                "When > 0, every fold gets this wavelength, m (0.01 to 2); 0 = off.", 0.0, 2.0);
    f.AddInt("fold_ramp_frames", &SynthOptions::fold_ramp_frames,
             "Folds grow from zero at frame 0 to full at this frame; 0 = full from frame 0 (a "
             "ramp leaves the reference frame's coarse mesh exact).",
             0);
    f.AddDouble("misalignment", &SynthOptions::misalignment,
                "Peak of the smooth random displacement added to the coarse meshes, m.", 0.0, 0.1);
    f.AddDouble("misalignment_wavelength", &SynthOptions::misalignment_wavelength,
                "Spatial wavelength of that displacement field, m.", 0.01, 100.0);
    f.AddDouble("max_displacement", &SynthOptions::max_displacement,
                "Largest |k| searched along a coarse normal for the true surface, m; farther is a "
                "miss.",
                1e-4, 10.0);
    f.AddEnum("coarse", &SynthOptions::coarse,
              "The coarse meshes: unfolded (the true surface without its folds), smoothed (the "
              "true surface Taubin-smoothed, synth.smoothing) or exact (the true surface at the "
              "coarse vertices, the detail between them missing).");
    f.AddSection("smoothing", &SynthOptions::smoothing, TaubinSmoothingOptions::Fields());
    f.AddSection("texture", &SynthOptions::texture, TextureOptions::Fields());
    f.AddSection("cameras", &SynthOptions::cameras, RigOptions::Fields());
    f.AddSection("render", &SynthOptions::render, RenderOptions::Fields());
    f.AddEnum("background", &SynthOptions::background,
              "Around the subject: plain (synth.render.background) or per_camera (a textured wall "
              "of its own in every camera).");
    f.AddBool("write_masks", &SynthOptions::write_masks,
              "Write the subject's silhouettes as foreground masks (masks/<camera>/).");
    f.AddCustom("seed",
                "Seed of every random choice (texture, misalignment, calibration and sensor "
                "noise).");
    return f;
  }();
  return fields;
}

void SynthOptions::Check() const {
  const std::string where = "SynthOptions::";
  Fields().CheckValues(*this, where);
  if (subject == SynthSubject::kSkirt) skirt.Check();
  if (subject == SynthSubject::kMesh) {
    Require(!mesh_path.empty(), where + "mesh_path", "must name a mesh file or folder");
    Require(IsPowerOfTwo(truth_refinement), where + "truth_refinement",
            "must be a power of two for a mesh subject (midpoint subdivision levels)");
  }
  for (size_t i = 0; i < folds.size(); ++i)
    folds[i].Check(where + "folds[" + std::to_string(i) + "]");
  // When on, the one wavelength replaces each fold's own: it keeps to a fold's range.
  const OptionField& fold_wavelength = FoldComponent::Fields().Field("wavelength");
  Require(single_wavelength == 0.0 || single_wavelength >= fold_wavelength.min,
          where + "single_wavelength",
          "must be 0 (off) or lie in [" + internal::CheckNumberText(fold_wavelength.min) + ", " +
              internal::CheckNumberText(fold_wavelength.max) + "] metres");
  smoothing.Check(where + "smoothing");
  texture.Check();
  cameras.Check();
  render.Check();
}

}  // namespace finecap
