// Synthetic captures with known true geometry: a textured cloth subject with procedural folds,
// filmed by a ring of calibrated cameras, together with the coarse input meshes a capture would
// provide and the ground truth that tells how much of the fine detail a solver recovered.
//
// World frame: metres, y points up, the subject stands around the vertical axis through its
// centre. Cameras follow camera.h. A capture folder written by GenerateSyntheticCapture:
//
//   cameras.yaml                  the rig as calibrated (calibration noise applied)
//   images/<camera>/<frame>.png   8-bit colour images, distorted with the rig's lens distortion
//   masks/<camera>/<frame>.png    with SynthOptions::write_masks: 255 where the subject covers at
//                                 least half of the pixel, else 0, distorted like the images
//   meshes/<frame>.ply            coarse input mesh: the true surface without its folds, a
//                                 smoothed copy of it, or the true surface at the coarse
//                                 vertices (SynthOptions::coarse)
//   gt/<frame>.ply                the true (finer) surface
//   gt/<frame>_k.txt              per coarse vertex: signed distance along its (area-weighted)
//                                 coarse normal to the true surface, metres; "nan" on a miss
//   gt/textureless.txt            coarse vertex ids inside the plain, textureless region
//
// Frames are named 000000, 000001, ... Everything is deterministic for a given `seed`.
#ifndef FINECAP_SYNTH_SYNTH_H_
#define FINECAP_SYNTH_SYNTH_H_

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "finecap/geometry/camera.h"
#include "finecap/geometry/mesh.h"
#include "finecap/geometry/mesh_smoothing.h"
#include "finecap/geometry/render.h"
#include "finecap/util/enum_names.h"
#include "finecap/util/option_fields.h"

namespace finecap {

// One family of parallel folds: a periodic displacement along the smooth surface normal.
//
// Folds live in the subject's material coordinates (angle theta around the vertical axis,
// distance h down the surface from its top, both taken in the first frame), so they move with the
// cloth. The phase is N * theta + 2 pi h sin(orientation) / wavelength + phase + drift * frame,
// with N = round(2 pi r cos(orientation) / wavelength) whole waves around the subject (r its mean
// radius): the folds close up seamlessly around the body, and on a flared skirt they fan out
// towards the hem (shorter than `wavelength` at the waist, longer at the hem) as real ones do.
// With orientation 90 the wavelength is exact everywhere.
// The cross-section of a fold (FoldComponent::profile): "sine" or "ridge".
enum class FoldProfile { kSine, kRidge };
const std::vector<EnumName<FoldProfile>>& EnumNames(FoldProfile);

// A family of folds. The fields are documented where Fields() declares them (docs/configuration.md:
// synth.folds); the comments below add what the documentation does not say.
struct FoldComponent {
  // Along the outward normal; a negative value flips the folds. Typical 0.002 to 0.02.
  double amplitude = 0.008;
  double wavelength = 0.12;  // Between neighbouring crests.
  // 0: waves travel around the subject, like the folds of a hanging skirt; 90: crests run around
  // it.
  double orientation = 0.0;
  double phase = 0.0;  // At frame 0.
  double drift = 6.0;  // The folds drift over the surface.
  // kRidge: sharp crests and broad troughs, zero mean, 4/pi * amplitude high and 2 - 4/pi below.
  FoldProfile profile = FoldProfile::kSine;

  static const OptionFields<FoldComponent>& Fields();  // option_fields.h
  // Throws Error naming `where` and the field when a value is out of range.
  void Check(const std::string& where) const;
};

// The built-in subject: a skirt-like flared tube, open at both ends (the paper's hardest case).
// The fields are documented where Fields() declares them (docs/configuration.md: synth.skirt);
// the comments below add what the documentation does not say.
struct SkirtOptions {
  double waist_radius = 0.14;
  double hem_radius = 0.36;
  double length = 0.6;
  double flare_exponent = 1.4;  // Larger values flare late.
  double waist_height = 1.0;
  // 64 x 40: 2560 vertices, ~4 cm apart at the hem.
  int around = 64;
  int down = 40;
  // The hem's outline wobbles into an ellipse (flare_wobble).
  double sway = 0.05;
  double swing = 10.0;
  double flare_wobble = 0.08;
  double period = 30.0;

  static const OptionFields<SkirtOptions>& Fields();  // option_fields.h
  void Check() const;
};

// The cloth print (TextureOptions::pattern): "mixed" (plaid, printed motifs and noise together),
// "plaid", "stripes", "print" or "noise".
enum class TexturePattern { kMixed, kPlaid, kStripes, kPrint, kNoise };
const std::vector<EnumName<TexturePattern>>& EnumNames(TexturePattern);

// The procedural cloth print, generated in texture (u, v) space. The fields are documented where
// Fields() declares them (docs/configuration.md: synth.texture).
struct TextureOptions {
  int width = 2048;
  int height = 1024;
  TexturePattern pattern = TexturePattern::kMixed;
  // textureless_end is at least textureless_begin.
  double textureless_begin = 0.0;
  double textureless_end = 0.0;
  Eigen::Vector3d textureless_color = Eigen::Vector3d(0.62, 0.55, 0.48);

  static const OptionFields<TextureOptions>& Fields();  // option_fields.h
  void Check() const;
};

// The camera rig: `count` cameras evenly spaced on a ring around the subject's vertical axis,
// each looking at the subject's centre. The fields are documented where Fields() declares them
// (docs/configuration.md: synth.cameras); the comments below add what the documentation does not
// say.
struct RigOptions {
  int count = 8;
  // 1004 x 1004: the paper's studio.
  int width = 1004;
  int height = 1004;
  // 1000: at the default distance of 3 m a surface Gaussian of 7 mm spans 2.3 pixels, as in the
  // paper's studio.
  double focal = 1000.0;
  double distance = 3.0;
  // Two values alternate high and low cameras.
  std::vector<double> heights = {0.4, -0.2};
  // Images are rendered undistorted and then distorted, so undistorting them with cameras.yaml
  // inverts it.
  std::array<double, 5> distortion = {0, 0, 0, 0, 0};
  // cameras.yaml states cameras perturbed from the true ones by these.
  double rotation_noise = 0.0;
  double translation_noise = 0.0;
  double focal_noise = 0.0;

  static const OptionFields<RigOptions>& Fields();  // option_fields.h
  void Check() const;
};

// What the coarse input meshes of a synthetic capture are.
enum class CoarseInput {
  // The true surface without its folds: the smooth surface the folds are added to, exact where
  // there are none (a template tracker that got everything but the folds right).
  kUnfolded,
  // The true surface at the coarse vertices (each coarse vertex is a vertex of the true mesh),
  // Taubin-smoothed over the coarse mesh: a smoothed copy of the true surface, as in the paper's
  // smoothed-input experiment. What smoothing leaves of the detail stays in the input, and the
  // input differs from the truth everywhere a little, as a real one does. With a detailed user
  // mesh sequence as the subject (truth_refinement 1, no folds) it is the sequence itself that
  // the coarse meshes smooth.
  kSmoothed,
  // The true surface at the coarse vertices (each coarse vertex is a vertex of the true mesh,
  // displaced by its fold), without smoothing: the input is exact at its vertices, and what it
  // lacks is the detail between them, which a coarse mesh cannot hold. The honest best case of
  // a coarse input (a tracker exact at its vertices); with a detailed user mesh sequence as the
  // subject (truth_refinement 1, no folds) it is the sequence itself.
  kExact,
};
// unfolded, smoothed, exact.
const std::vector<EnumName<CoarseInput>>& EnumNames(CoarseInput);

// What a synthetic capture shows (SynthOptions::subject): "skirt" (the built-in flared tube) or
// "mesh" (meshes from files).
enum class SynthSubject { kSkirt, kMesh };
const std::vector<EnumName<SynthSubject>>& EnumNames(SynthSubject);

// What the cameras see around the subject (SynthOptions::background): "plain" (one colour,
// render.background) or "per_camera" (a textured wall of its own behind the subject in every
// camera, so that no two cameras agree on the background: what a real studio's walls, floor and
// crew do to a similarity that compares cameras).
enum class SynthBackground { kPlain, kPerCamera };
const std::vector<EnumName<SynthBackground>>& EnumNames(SynthBackground);

// The fields are documented where Fields() declares them (docs/configuration.md: synth); the
// comments below add what the documentation does not say.
struct SynthOptions {
  SynthSubject subject = SynthSubject::kSkirt;
  SkirtOptions skirt;
  // A mesh file: the subject stands still; a folder: taken in name order. The true surface is
  // each frame's midpoint subdivision with folds added along interpolated normals
  // (truth_refinement 1 and no folds: the mesh itself); the coarse input is the mesh itself, or
  // its smoothed copy (see `coarse`; exact: the mesh itself).
  std::string mesh_path;
  int num_frames = 5;
  // Per axis. A power of two for "mesh": midpoint subdivision levels.
  int truth_refinement = 4;

  // Three families of 8-20 cm waves in different directions.
  std::vector<FoldComponent> folds = {
      {0.009, 0.16, 0.0, 0.0, 5.0, FoldProfile::kSine},
      {0.006, 0.10, 25.0, 40.0, -7.0, FoldProfile::kRidge},
      {0.004, 0.20, 70.0, 120.0, 4.0, FoldProfile::kSine},
  };
  // Captures with one fold scale.
  double single_wavelength = 0.0;
  // With a ramp the reference frame (frame 0, whose images colour the surface) has an exact
  // coarse mesh, which a real capture never has: it flatters the refinement, and is kept for
  // comparison (configs/synth_skirt_ramp.yaml).
  int fold_ramp_frames = 0;

  CoarseInput coarse = CoarseInput::kUnfolded;
  TaubinSmoothingOptions smoothing;  // When `coarse` is kSmoothed.

  // The field is 3D and fixed to the material: the input's low-frequency misalignment.
  double misalignment = 0.0;
  double misalignment_wavelength = 0.5;
  // When casting a coarse vertex's normal against the true surface.
  double max_displacement = 0.1;

  TextureOptions texture;
  RigOptions cameras;
  // The noise seed of each image is derived from `seed`, the frame and the camera together with
  // render.noise_seed. DefaultRenderOptions: supersampling 3, shading on (ambient 0.5, diffuse
  // 0.6), background dark grey.
  RenderOptions render = DefaultRenderOptions();
  SynthBackground background = SynthBackground::kPlain;
  bool write_masks = false;  // masks/, by GenerateSyntheticCapture.

  std::uint64_t seed = 1;

  static const OptionFields<SynthOptions>& Fields();  // option_fields.h
  // Throws Error("SynthOptions::<field>", problem) for the first invalid value.
  void Check() const;

  static RenderOptions DefaultRenderOptions();
};

// The ground truth of one frame, in memory.
struct SyntheticFrame {
  Mesh coarse;  // The input mesh: unfolded, smoothed or exact (SynthOptions::coarse),
                // misaligned when asked.
  Mesh truth;   // The true, finer surface.
  // Per coarse vertex: signed distance along its coarse normal to `truth`; NaN on a miss.
  Eigen::VectorXd true_k;
  // Per coarse vertex: the fold displacement at its material point, metres, applied along
  // `smooth_normals` (what true_k measures when the coarse input is unfolded and the coarse and
  // smooth normals agree).
  Eigen::VectorXd folds_at_coarse;
  // Per coarse vertex: unit normal of the smooth (unfolded) surface.
  Eigen::Matrix3Xd smooth_normals;
};

// A synthetic capture held in memory: frames and images are made on demand.
class SyntheticCapture {
 public:
  // Checks the options, reads user meshes, builds the texture and the rig. Throws Error on
  // invalid options or unreadable meshes.
  explicit SyntheticCapture(const SynthOptions& options);
  ~SyntheticCapture();

  int num_frames() const;
  // The cameras the images are rendered with (exact).
  const std::vector<Camera>& true_cameras() const;
  // The cameras as written to cameras.yaml: calibration noise applied, distortion included.
  const std::vector<Camera>& calibrated_cameras() const;
  // Coarse vertex ids whose surroundings are plain (the textureless band); sorted.
  const std::vector<int>& textureless_vertices() const;
  // The texture image (BGR) and per-corner UVs of the true mesh.
  const SurfaceAppearance& appearance() const;

  // Geometry and ground truth of frame `index` (0 <= index < num_frames()).
  SyntheticFrame Frame(int index) const;
  // The image camera `camera` records of `frame` (number `index`): BGR, lens distortion applied.
  // When `mask` is given it receives the subject's silhouette in that image: CV_8UC1, 255 where
  // the subject covers at least half of the pixel (its anti-aliased coverage), else 0.
  cv::Mat Image(const SyntheticFrame& frame, int index, int camera, cv::Mat* mask = nullptr) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Writes a complete capture (layout at the top of this file) into `out_dir`, which must not
// exist or be empty: nothing a user has is ever overwritten. Every file is written atomically.
// Throws Error naming the folder or file and the problem.
void GenerateSyntheticCapture(const SynthOptions& options, const std::string& out_dir);

}  // namespace finecap

#endif  // FINECAP_SYNTH_SYNTH_H_
