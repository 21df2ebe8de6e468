// Validation of the synthetic capture options, and of the smoothing they use (mesh_smoothing.h):
// pure checks, apart from the generator's code, so that reading a config links no geometry (the
// config fuzzer builds from the parser sources alone).
#include <cmath>
#include <string>

#include "finecap/geometry/mesh_smoothing.h"
#include "finecap/synth/synth.h"
#include "finecap/util/error.h"
#include "util/option_checks.h"

namespace finecap {
namespace {

using internal::RequireFieldFinite;
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

void TaubinSmoothingOptions::Check(const std::string& where) const {
  Require(iterations >= 1 && iterations <= 100000, where + ".iterations",
          "is " + std::to_string(iterations) + " but must lie in [1, 100000]");
  RequireFieldRange(lambda, 1e-3, 1.0, where + ".lambda");
  RequireFieldRange(mu, -1.0, 0.0, where + ".mu");
  // The fastest wave a mesh carries (Laplacian eigenvalue 2) is scaled by this per iteration;
  // below -1 it would grow from one iteration to the next instead of fading.
  const double fastest = (1.0 - 2.0 * lambda) * (1.0 - 2.0 * mu);
  Require(fastest >= -1.0, where + ".mu",
          "is " + std::to_string(mu) + " with lambda " + std::to_string(lambda) +
              ": together they make the smoothing unstable ((1 - 2 lambda)(1 - 2 mu) = " +
              std::to_string(fastest) + " < -1, the finest detail grows); use a smaller lambda " +
              "or |mu|");
}

void FoldComponent::Check(const std::string& where) const {
  RequireFieldRange(amplitude, -0.1, 0.1, where + ".amplitude");
  RequireFieldRange(wavelength, 0.01, 2.0, where + ".wavelength");
  RequireFieldFinite(orientation, where + ".orientation");
  RequireFieldFinite(phase, where + ".phase");
  RequireFieldFinite(drift, where + ".drift");
  internal::RequireKnownChoice(profile, where + ".profile");
}

void SkirtOptions::Check() const {
  const std::string where = "SkirtOptions::";
  RequireFieldRange(waist_radius, 0.01, 5.0, where + "waist_radius");
  RequireFieldRange(hem_radius, waist_radius, 5.0, where + "hem_radius");
  RequireFieldRange(length, 0.01, 10.0, where + "length");
  RequireFieldRange(flare_exponent, 1.0, 10.0, where + "flare_exponent");
  RequireFieldFinite(waist_height, where + "waist_height");
  Require(around >= 8 && around <= 100000, where + "around", "must lie in [8, 100000]");
  Require(down >= 3 && down <= 100000, where + "down", "must lie in [3, 100000]");
  RequireFieldRange(sway, 0.0, 1.0, where + "sway");
  RequireFieldRange(swing, -90.0, 90.0, where + "swing");
  RequireFieldRange(flare_wobble, 0.0, 0.5, where + "flare_wobble");
  RequireFieldRange(period, 1e-3, 1e9, where + "period");
}

void TextureOptions::Check() const {
  const std::string where = "TextureOptions::";
  Require(width >= 16 && width <= 16384, where + "width", "must lie in [16, 16384]");
  Require(height >= 16 && height <= 16384, where + "height", "must lie in [16, 16384]");
  internal::RequireKnownChoice(pattern, where + "pattern");
  RequireFieldRange(textureless_begin, 0.0, 1.0, where + "textureless_begin");
  RequireFieldRange(textureless_end, textureless_begin, 1.0, where + "textureless_end");
  Require(textureless_color.allFinite() && textureless_color.minCoeff() >= 0.0 &&
              textureless_color.maxCoeff() <= 1.0,
          where + "textureless_color", "must be RGB in [0, 1]");
}

void RigOptions::Check() const {
  const std::string where = "RigOptions::";
  Require(count >= 1 && count <= 1000, where + "count", "must lie in [1, 1000]");
  Require(width >= 16 && width <= 20000, where + "width", "must lie in [16, 20000]");
  Require(height >= 16 && height <= 20000, where + "height", "must lie in [16, 20000]");
  RequireFieldRange(focal, 1.0, 1e6, where + "focal");
  RequireFieldRange(distance, 0.05, 1e4, where + "distance");
  Require(!heights.empty(), where + "heights", "must list at least one height");
  for (double h : heights) RequireFieldFinite(h, where + "heights");
  for (double d : distortion) RequireFieldRange(d, -10.0, 10.0, where + "distortion");
  RequireFieldRange(rotation_noise, 0.0, 10.0, where + "rotation_noise");
  RequireFieldRange(translation_noise, 0.0, 1.0, where + "translation_noise");
  RequireFieldRange(focal_noise, 0.0, 0.5, where + "focal_noise");
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

void SynthOptions::Check() const {
  const std::string where = "SynthOptions::";
  internal::RequireKnownChoice(subject, where + "subject");
  internal::RequireKnownChoice(coarse, where + "coarse");
  internal::RequireKnownChoice(background, where + "background");
  if (subject == SynthSubject::kSkirt) skirt.Check();
  if (subject == SynthSubject::kMesh) {
    Require(!mesh_path.empty(), where + "mesh_path", "must name a mesh file or folder");
    Require(IsPowerOfTwo(truth_refinement), where + "truth_refinement",
            "must be a power of two for a mesh subject (midpoint subdivision levels)");
  }
  Require(num_frames >= 1 && num_frames <= 1000000, where + "num_frames", "must be at least 1");
  Require(truth_refinement >= 1 && truth_refinement <= 16, where + "truth_refinement",
          "must lie in [1, 16]");
  for (size_t i = 0; i < folds.size(); ++i)
    folds[i].Check(where + "folds[" + std::to_string(i) + "]");
  Require(single_wavelength == 0.0 || (single_wavelength >= 0.01 && single_wavelength <= 2.0),
          where + "single_wavelength", "must be 0 (off) or lie in [0.01, 2] metres");
  Require(fold_ramp_frames >= 0, where + "fold_ramp_frames", "must be >= 0");
  RequireFieldRange(misalignment, 0.0, 0.1, where + "misalignment");
  RequireFieldRange(misalignment_wavelength, 0.01, 100.0, where + "misalignment_wavelength");
  RequireFieldRange(max_displacement, 1e-4, 10.0, where + "max_displacement");
  smoothing.Check(where + "smoothing");
  texture.Check();
  cameras.Check();
  render.Check();
}

}  // namespace finecap
