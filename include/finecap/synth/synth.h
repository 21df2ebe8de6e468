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

struct FoldComponent {
  // Peak displacement along the outward normal, metres; a negative value flips the folds.
  // Typical 0.002 to 0.02. Default 0.008.
  double amplitude = 0.008;
  // Distance between neighbouring crests, metres (0.01 to 1). Default 0.12.
  double wavelength = 0.12;
  // Direction of the crests, degrees: 0 = crests run down the subject (waves travel around it,
  // like the folds of a hanging skirt); 90 = crests run around it. Default 0.
  double orientation = 0.0;
  // Phase at frame 0, degrees. Default 0.
  double phase = 0.0;
  // Phase change per frame, degrees: the folds drift over the surface. Default 6.
  double drift = 6.0;
  // Cross-section of a fold: kSine, or kRidge (sharp crests and broad troughs, zero mean,
  // 4/pi * amplitude high and 2 - 4/pi below). Default kSine.
  FoldProfile profile = FoldProfile::kSine;

  // Throws Error naming `where` and the field when a value is out of range.
  void Check(const std::string& where) const;
};

// The built-in subject: a skirt-like flared tube, open at both ends (the paper's hardest case).
struct SkirtOptions {
  // Radius at the waist (top), metres. Default 0.14.
  double waist_radius = 0.14;
  // Radius at the hem (bottom), metres, >= waist_radius. Default 0.36.
  double hem_radius = 0.36;
  // Height from waist to hem, metres. Default 0.6.
  double length = 0.6;
  // Shape of the flare: radius grows like s^flare_exponent from waist (s = 0) to hem (s = 1);
  // 1 is a cone, larger values flare late. Default 1.4.
  double flare_exponent = 1.4;
  // Height of the waist above the floor (world y), metres. Default 1.0.
  double waist_height = 1.0;
  // Coarse mesh resolution: vertices around the tube and from waist to hem (>= 8 and >= 3).
  // Defaults 64 and 40 (2560 vertices, ~4 cm apart at the hem).
  int around = 64;
  int down = 40;
  // Low-frequency motion, one cycle every `period` frames: the hem sways sideways by up to
  // `sway` metres, twists about the vertical axis by up to `swing` degrees, and its outline
  // wobbles into an ellipse whose radii differ by up to `flare_wobble` (a fraction) from round.
  // Defaults 0.05 m, 10 degrees, 0.08, 30 frames.
  double sway = 0.05;
  double swing = 10.0;
  double flare_wobble = 0.08;
  double period = 30.0;

  void Check() const;
};

// The cloth print (TextureOptions::pattern): "mixed" (plaid, printed motifs and noise together),
// "plaid", "stripes", "print" or "noise".
enum class TexturePattern { kMixed, kPlaid, kStripes, kPrint, kNoise };
const std::vector<EnumName<TexturePattern>>& EnumNames(TexturePattern);

// The procedural cloth print, generated in texture (u, v) space.
struct TextureOptions {
  // Texture image size in texels. Defaults 2048 x 1024.
  int width = 2048;
  int height = 1024;
  // The print. Default kMixed.
  TexturePattern pattern = TexturePattern::kMixed;
  // A band of the surface painted in one plain colour: from textureless_begin to textureless_end,
  // as fractions of the subject's height measured from its top (0 to 1). No band when they are
  // equal. Defaults 0 and 0.
  double textureless_begin = 0.0;
  double textureless_end = 0.0;
  // Colour of that band, RGB in [0, 1]. Default (0.62, 0.55, 0.48).
  Eigen::Vector3d textureless_color = Eigen::Vector3d(0.62, 0.55, 0.48);

  void Check() const;
};

// The camera rig: `count` cameras evenly spaced on a ring around the subject's vertical axis,
// each looking at the subject's centre.
struct RigOptions {
  // Number of cameras (>= 1). Default 8.
  int count = 8;
  // Image size in pixels. Defaults 1004 x 1004 (the paper's studio).
  int width = 1004;
  int height = 1004;
  // Focal length in pixels. Default 1000: at the default distance of 3 m a surface Gaussian of
  // 7 mm spans 2.3 pixels, as in the paper's studio.
  double focal = 1000.0;
  // Horizontal distance from the subject's axis, metres. Default 3.
  double distance = 3.0;
  // Heights of the cameras above the subject's centre, metres; camera c uses
  // heights[c % heights.size()], so two values alternate high and low cameras. Default {0.4, -0.2}.
  std::vector<double> heights = {0.4, -0.2};
  // Lens distortion (k1, k2, p1, p2, k3) of every camera (OpenCV's model): images are rendered
  // undistorted and then distorted, so undistorting them with cameras.yaml inverts it. Default 0.
  std::array<double, 5> distortion = {0, 0, 0, 0, 0};
  // Calibration noise: cameras.yaml states cameras perturbed from the true ones by a random
  // rotation (standard deviation per axis, degrees), centre offset (per axis, metres) and
  // relative focal length error. Defaults 0.
  double rotation_noise = 0.0;
  double translation_noise = 0.0;
  double focal_noise = 0.0;

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

struct SynthOptions {
  // kSkirt (the built-in flared tube, see `skirt`) or kMesh (the meshes at `mesh_path`).
  // Default kSkirt.
  SynthSubject subject = SynthSubject::kSkirt;
  SkirtOptions skirt;
  // For subject "mesh": a mesh file (the subject stands still) or a folder of per-frame meshes
  // sharing one topology, taken in name order (.ply, .obj, .off, .stl). World y must point up.
  // The true surface is each frame's midpoint subdivision with folds added along interpolated
  // normals (truth_refinement 1 and no folds: the mesh itself); the coarse input is the mesh
  // itself, or its smoothed copy (see `coarse`; exact: the mesh itself). Default empty.
  std::string mesh_path;
  // Number of frames (>= 1; at most the number of meshes in a `mesh_path` folder). Default 5.
  int num_frames = 5;
  // Resolution of the true surface relative to the coarse mesh, per axis (edges per coarse
  // edge). Any integer >= 1 for the skirt; a power of two for "mesh" (midpoint subdivision
  // levels). Default 4.
  int truth_refinement = 4;

  // The folds, summed. Default: three families of 8-20 cm waves in different directions.
  std::vector<FoldComponent> folds = {
      {0.009, 0.16, 0.0, 0.0, 5.0, FoldProfile::kSine},
      {0.006, 0.10, 25.0, 40.0, -7.0, FoldProfile::kRidge},
      {0.004, 0.20, 70.0, 120.0, 4.0, FoldProfile::kSine},
  };
  // When > 0, every fold gets this wavelength (metres): captures with one fold scale. Default 0.
  double single_wavelength = 0.0;
  // Fold amplitudes grow smoothly from zero at frame 0 to full at this frame; 0 gives full folds
  // from frame 0. With a ramp the reference frame (frame 0, whose images colour the surface) has
  // an exact coarse mesh, which a real capture never has: it flatters the refinement, and is kept
  // for comparison (configs/synth_skirt_ramp.yaml). Default 0.
  int fold_ramp_frames = 0;

  // What the coarse meshes are (see CoarseInput). Default kUnfolded.
  CoarseInput coarse = CoarseInput::kUnfolded;
  // The smoothing of the coarse meshes when `coarse` is kSmoothed (its iterations are the
  // strength). Default: 30 iterations, lambda 0.5, mu -0.5025.
  TaubinSmoothingOptions smoothing;

  // Peak of a smooth random displacement field (3D, fixed to the material) added to the coarse
  // meshes: the input's low-frequency misalignment, metres. Default 0.
  double misalignment = 0.0;
  // Spatial wavelength of that field, metres (> 0). Default 0.5.
  double misalignment_wavelength = 0.5;
  // Largest |k| searched when casting a coarse vertex's normal against the true surface,
  // metres (> 0); farther hits are reported as misses. Default 0.1.
  double max_displacement = 0.1;

  TextureOptions texture;
  RigOptions cameras;
  // How images are rendered (supersampling, shading, sensor noise, background). The noise seed
  // of each image is derived from `seed`, the frame and the camera together with
  // render.noise_seed. Default: supersampling 3, shading on (ambient 0.5, diffuse 0.6),
  // background dark grey.
  RenderOptions render = DefaultRenderOptions();
  // The background of the images (see SynthBackground). Default kPlain.
  SynthBackground background = SynthBackground::kPlain;
  // Whether GenerateSyntheticCapture writes the foreground masks (masks/). Default false.
  bool write_masks = false;

  // Seed of every random choice (texture, misalignment, calibration and sensor noise). Default 1.
  std::uint64_t seed = 1;

  // Throws Error("synth.<field>", problem) for the first invalid value.
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
