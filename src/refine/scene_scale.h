// The scale of a capture, and the lengths that follow from it.
//
// The refinement's lengths (sigma_hat, k_max, the depth tolerance of the visibility test, the
// gradient ascent's steps) only make sense relative to the subject: 7 mm Gaussians suit a person
// meshed with 10k vertices and filmed from 3 m, not a 10 cm figurine. Unless a config sets them,
// they follow from one scene length measured on the reference frame (MeasureSceneScale):
//
//   scene length s = max(mean edge length of the subdivided mesh, 3 * pixel footprint),
//
// the pixel footprint being the median, over the cameras and the fine vertices each sees in its
// image, of depth / focal length (the metres one pixel covers at the surface). The edge length
// says how densely surface Gaussians sample the surface; the footprint floor keeps a Gaussian
// wide enough (at least 1.3 pixels, wider than the finest image Gaussians) for the image model
// to see. Each length is a fixed multiple of s (SceneLengthFactors), chosen so that the
// person-sized presets keep the values finecap used before it measured the scene (k_max 2 cm:
// synth_skirt's s is 11.4 mm; sigma_hat 7 mm under the similarities that compare single
// Gaussians, 5 mm under consensus, which compares patches).
//
// Also a guard against captures in the wrong unit. finecap's lengths are metres (its outputs,
// the synthetic folds), so a capture in millimetres or centimetres would not fail anywhere: with
// lengths set in metres its Gaussians would simply be 1000 or 100 times too small to see
// anything. The size of the coarse mesh against sigma_hat tells the units apart: a performer in
// metres spans a few hundred sigma_hat. (Lengths that follow from the scene would fit a capture in
// millimetres too, but its outputs would not be metres; the commands measure the mesh against
// the person-sized 7 mm then, so such a capture is still refused.)
#ifndef FINECAP_REFINE_SCENE_SCALE_H_
#define FINECAP_REFINE_SCENE_SCALE_H_

#include <string>
#include <vector>

#include "finecap/geometry/camera.h"
#include "finecap/geometry/mesh.h"
#include "finecap/refine/refine.h"

namespace finecap {

class Capture;

// What MeasureSceneScale measures, in the capture's units (metres).
struct SceneScale {
  double diagonal = 0.0;          // Bounding-box diagonal of the mesh.
  double mean_edge_length = 0.0;  // Mean edge length of the subdivided mesh.
  // Median over (camera, fine vertex in front of it and inside its image) of depth / focal
  // length; 0 when no camera sees any vertex.
  double pixel_footprint = 0.0;
  // max(mean_edge_length, kFootprintsPerSceneLength * pixel_footprint).
  double length = 0.0;
};

// The scene length is never less than this many pixel footprints.
constexpr double kFootprintsPerSceneLength = 3.0;

// Each length that follows from the scene, as a multiple of the scene length s.
struct SceneLengthFactors {
  // sigma_hat under the consensus similarity: 5.0 mm on synth_skirt (s = 11.4 mm), 0.52 mm on
  // the temple. Its residuals compare patches (a Gaussian with its one-ring), which already
  // average over a window, so each Gaussian needs less blur than one compared alone. 0.6 of s
  // recovered 2 to 6 points less detail on synth_skirt, its ramped variant and the single 5 and
  // 10 cm folds, and as much on synth_noisy and (held-out NCC) the temple.
  double sigma_hat = 0.44;
  // sigma_hat under surface_color and paper, which compare single Gaussians: 6.8 mm, 0.71 mm.
  double single_gaussian_sigma_hat = 0.6;
  // k_max is also at least this fraction of the mesh's bounding-box diagonal: how far a coarse
  // input lies from the truth depends on how it was made (a body model's fit, a template's
  // tracking, a visual hull, all off by a few per cent of the subject's size), not on how densely
  // it is meshed. 24 mm on synth_skirt (1.18 m across), 4.1 mm on the temple (0.2 m), whose
  // visual hull lies up to a centimetre outside its concavities.
  double k_max = 1.75;  // 20 mm; 2.1 mm.
  double k_max_of_diagonal = 0.02;
  double depth_tolerance = 0.9;  // 10 mm; 1.1 mm.
  double initial_step = 0.045;   // 0.51 mm; 0.054 mm.
  double max_step = 0.175;       // 2.0 mm; 0.21 mm.
};

// Measures `fine` (a subdivided mesh) as seen by `cameras`.
SceneScale MeasureSceneScale(const Mesh& fine, const std::vector<Camera>& cameras);

// One length of RefineOptions as a run uses it.
struct ChosenLength {
  std::string field;        // The options field, e.g. "RefineOptions::sigma_hat".
  double value = 0.0;       // Metres.
  bool from_scene = false;  // Followed from the scene (else set explicitly).
};

struct SceneScaleDefaults {
  SceneScale scale;
  std::vector<ChosenLength> lengths;  // Every length of RefineOptions::scene_lengths' kind.
};

// Fills in every length of `*options` that `options->scene_lengths` marks as following from the
// scene; lengths set explicitly stay. The marks stay too, so resolving again (on the same scene)
// changes nothing. `reference_coarse` is the coarse mesh of the reference frame, subdivided here
// as options->subdivision and options->subdivision_levels say; `where` names it in errors.
// Returns what was measured and every length as chosen.
SceneScaleDefaults ResolveSceneScaleDefaults(const Mesh& reference_coarse,
                                             const std::vector<Camera>& cameras,
                                             const std::string& where, RefineOptions* options);

// The same for a capture's frame `reference_frame` (an index into its sorted frame list).
SceneScaleDefaults ResolveSceneScaleDefaults(const Capture& capture, int reference_frame,
                                             RefineOptions* options);

// A length for people: "0.716 mm", "207 mm", "1.18 m".
std::string LengthText(double metres);

// A line that says what was chosen and from what, e.g. "scene length 9.9 mm (mean edge 9.9 mm,
// pixel footprint 3.0 mm); RefineOptions::sigma_hat 6.93 mm (from the scene), EnergyOptions::k_max
// 20 mm (set)".
std::string DescribeSceneScaleDefaults(const SceneScaleDefaults& defaults);

struct SceneScaleLimits {
  // The smallest bounding-box diagonal of a coarse mesh accepted, in multiples of sigma_hat.
  // Default 5 (3.5 cm with the default sigma_hat of 7 mm): smaller, a surface Gaussian covers
  // the whole subject. Must be positive.
  double min_sigmas = 5.0;
  // The largest, in multiples of sigma_hat. Default 3000 (21 m with the default sigma_hat): a
  // 1.7 m performer spans ~300; the same performer in centimetres ~30,000, in millimetres
  // ~300,000. Must exceed min_sigmas.
  double max_sigmas = 3000.0;

  void Check() const;
};

// The diagonal of the axis-aligned bounding box of `mesh`'s vertices, in the mesh's units.
double BoundingBoxDiagonal(const Mesh& mesh);

// Throws Error(where, ...) when the bounding-box diagonal of `mesh` lies outside
// [limits.min_sigmas, limits.max_sigmas] * sigma_hat, saying how large the mesh is, which unit it
// looks like and what to do (convert the capture to metres, or change model.sigma_hat for a
// subject of unusual size). `where` should name the mesh file. `sigma_hat` must be positive.
void RequirePlausibleSceneScale(const Mesh& mesh, double sigma_hat, const std::string& where,
                                const SceneScaleLimits& limits = {});

}  // namespace finecap

#endif  // FINECAP_REFINE_SCENE_SCALE_H_
