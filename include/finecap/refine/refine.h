// Per-frame refinement, the product's main job, independent of files and flags: subdivide the
// coarse mesh, find what each camera sees, build the image Gaussians, set up the energy, solve
// for the displacement k of every refined vertex along its normal, and apply it.
//
// Data flows one way: the caller reads a frame (coarse mesh, images) and writes the result.
// What stays fixed over a sequence (topology, subdivision stencil, neighbourhoods, the refined
// vertices, the reference colours) lives in SequenceModel and is computed once.
#ifndef FINECAP_REFINE_REFINE_H_
#define FINECAP_REFINE_REFINE_H_

#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "finecap/energy/energy_options.h"
#include "finecap/energy/frame_energy.h"
#include "finecap/geometry/camera.h"
#include "finecap/geometry/mesh.h"
#include "finecap/geometry/neighbourhood.h"
#include "finecap/geometry/subdivision.h"
#include "finecap/model/image_gaussians.h"
#include "finecap/model/surface_gaussians.h"
#include "finecap/model/visibility.h"
#include "finecap/solvers/solver.h"
#include "finecap/solvers/sweep.h"
#include "finecap/util/enum_names.h"
#include "finecap/util/option_fields.h"

namespace finecap {

// Leaves down to one pixel: the smallest image Gaussians then blur by half a pixel instead of one.
// That blur lies on each camera's own pixel grid, so it differs between cameras and the consensus
// similarity counts it as disagreement; next to a projected surface Gaussian of 1.3-1.7 px (the
// synthetic studio, sigma_hat at 3 m) it was the energy's noise floor wherever the input is
// within a pixel of the truth (the samba dancer's smoothed input: -4.9 % with 2 px leaves,
// +16 % with 1 px; docs/method.md's consensus table). configs/surface_color.yaml keeps 2 px.
inline ImageGaussianOptions RefinementImageOptions() {
  ImageGaussianOptions options;
  options.min_leaf_size = 1;
  options.color_space = ColorSpace::kNormalizedRgb;
  return options;
}

// A coarse-to-fine schedule within each frame: the energy is solved first with wider surface
// Gaussians and a coarser image model (sigma_hat and the smallest quad-tree leaf multiplied by
// scale^level), each level starting where the coarser one ended. A wider Gaussian reaches a fold
// further from the input surface before the fine level sharpens it; the paper names such local
// maxima as its main limitation. The reference colours are the configured level's throughout.
// The fields are documented where Fields() declares them (docs/configuration.md:
// refine.coarse_to_fine).
struct CoarseToFineOptions {
  int levels = 1;  // The configured level included.
  double scale = 2.0;

  static const OptionFields<CoarseToFineOptions>& Fields();  // option_fields.h
  void Check() const;
};

// The cameras aligned with each other before the detail stage reads them: per frame and camera,
// a shift of the principal point (camera_alignment.h in src/refine says why and how). The fields
// are documented where Fields() declares them (docs/configuration.md: refine.camera_alignment).
struct CameraAlignmentOptions {
  int max_rounds = 10;  // 0: the cameras as given.

  static const OptionFields<CameraAlignmentOptions>& Fields();  // option_fields.h
  void Check() const;
};

// Which lengths of RefineOptions follow from the scene's scale (scene_scale.h) instead of the
// values their fields hold. Until ResolveSceneScaleDefaults replaces it, a marked field holds the
// person-sized value finecap used before it measured the scene, and that is what RefineFrame
// uses; a caller who sets such a length clears its mark. Default: every length follows the scene.
struct SceneLengths {
  bool sigma_hat = true;        // RefineOptions::sigma_hat (model.sigma_hat).
  bool k_max = true;            // energy.k_max.
  bool depth_tolerance = true;  // visibility.depth_tolerance.
  bool initial_step = true;     // solver.initial_step.
  bool max_step = true;         // solver.max_step.
};

// The options of refining a frame. Its own fields are documented where ModelFields() and
// RunFields() declare them (docs/configuration.md: model, refine); the comments below add what the
// documentation does not say.
struct RefineOptions {
  // The paper subdivided its 1.5k-2.5k-vertex meshes to 6k-10k vertices with Loop's scheme: 1
  // level.
  int subdivision_levels = 1;
  SubdivisionScheme subdivision = SubdivisionScheme::kLoop;  // subdivision.h
  double sigma_hat = 0.007;  // Follows from the scene unless set (scene_lengths).
  // kPixels: the mean of the pixels under the projected Gaussian in the best-aligned camera;
  // kImageModel: see ComputeModelReferenceColors.
  ReferenceColorSource reference_colors = ReferenceColorSource::kImageModel;
  // The shrink is the Gaussians' extent's (the paper's section 6). Off: the surface-colour
  // similarity has no such shrink (configs/paper.yaml turns it on).
  bool bias_compensation = false;
  // Also when the solver ends with a lower energy than it started from: the run's own measure
  // says the frame got worse. The stats record flags such frames either way.
  bool keep_input_if_worse = false;
  bool warm_start = false;  // From the previous frame's k instead of from zero.
  // Each pass of the detail stage after the first has an energy of its own, prepared at the
  // surface the pass before found (visibility, view angles, camera alignment).
  bool views_follow_surface = true;

  // A plane-sweep search for each Gaussian's starting displacement (sweep.h).
  SweepOptions sweep;
  CoarseToFineOptions coarse_to_fine;
  CameraAlignmentOptions camera_alignment;

  // The image model. Defaults differ from ImageGaussianOptions' (the paper's) in two measured
  // ways: leaves down to 2 px (sigma 1 px) keep the texture detail the similarity needs, and
  // colours are normalized RGB, which keeps brightness: within one frame a matte surface's
  // shading is the same in every camera, so the consensus similarity may compare it, and a grey
  // object has texture only there (surface_color, which compares one frame with another, used
  // chromaticity; configs/surface_color.yaml).
  ImageGaussianOptions image = RefinementImageOptions();
  VisibilityOptions visibility;
  EnergyOptions energy;
  SolverOptions solver;
  // The lengths above that are still to follow from the scene.
  SceneLengths scene_lengths;

  // The fields of the surface model (config section `model`), and those of the run (section
  // `refine`, with coarse_to_fine and sweep): option_fields.h.
  static const OptionFields<RefineOptions>& ModelFields();
  static const OptionFields<RefineOptions>& RunFields();
  void Check() const;
};

// One frame's input: the coarse mesh and, per camera, the pinhole camera and its undistorted
// 8-bit BGR image, and optionally its foreground mask.
//
// Masks. Background pixels take no part in the energy, in ways that together leave the result
// unchanged whatever the background holds: the image models are built from foreground pixels
// only (BuildImageGaussians), so no image Gaussian carries a background colour; and in the
// image-model stage a camera sees a vertex only where the vertex projects onto its foreground,
// so a surface Gaussian that falls on the background in one camera is compared in the others
// alone, not against the absence of image Gaussians there. What reads pixels directly (the
// detail stage's samples, reference colours from pixels) reads the images with their background
// painted black, so that no blur or bilinear read near a silhouette takes anything from what the
// background holds; and a detail sample counts as off a camera's foreground where it falls on
// the mask shrunk by the reach of its reads (PrepareDetailEnergy), so that it does not read
// that black either. A patch cut by a mask is compared on its samples that every camera
// comparing it has on its foreground (PixelConsensusSimilarity), not dropped: along a
// silhouette every camera cuts the patches at the subject's edge, and dropping them left a band
// along the hem of a skirt without data. Which cameras see a vertex at all, for the detail
// stage and the confidence, is decided by the geometry alone: the input may be off by a few
// pixels at a silhouette, where its vertex then falls on the background of a camera that does
// see the surface it stands for.
struct FrameInput {
  Mesh coarse;
  std::vector<Camera> cameras;
  std::vector<cv::Mat> images;
  // Empty (no masks), or one CV_8UC1 per camera of its image's size, non-zero on the foreground.
  std::vector<cv::Mat> masks;
  // The images' models, one per camera, when already built (ModelFrameImages), with the options
  // they were built with; empty otherwise. A frame's images are then modelled once, however many
  // stages use them (the reference colours, the forecast, the solve), and can be modelled ahead,
  // while the frame before is solved.
  std::vector<ImageGaussians> image_models;
  ImageGaussianOptions image_model_options;
  // The solved displacement of the frame before, one per fine vertex (NaN where not refined),
  // for the energy's terms that read it (SimilarityNeeds::reads_frame_before); empty: none. Set
  // only once that frame is solved, so it is never part of what is read or prepared ahead.
  Eigen::VectorXd frame_before_k;
  // With energy.consensus.shared_appearance: the colours the frame before's refined surface
  // showed at its surface samples (FrameResult::appearance); empty: none, and ignored when this
  // frame's samples differ in number (another sampling level). Set as frame_before_k.
  Eigen::Matrix3Xd frame_before_appearance;
};

// Builds input->image_models under `options`, unless they are already built with them.
void ModelFrameImages(const ImageGaussianOptions& options, FrameInput* input);

// The image models of `input` under `options`: a copy of its own when built with them, else
// built now.
std::vector<ImageGaussians> FrameImageModels(const FrameInput& input,
                                             const ImageGaussianOptions& options);

// The parts of the model that stay fixed over a sequence.
class SequenceModel {
 public:
  // `first_coarse` fixes the topology; `coarse_mask` lists the coarse vertex ids to refine
  // (empty: all). Throws Error naming `where` when the mesh cannot be subdivided.
  SequenceModel(const Mesh& first_coarse, const std::vector<int>& coarse_mask,
                const RefineOptions& options, const std::string& where);

  // The subdivided mesh of a frame and its area-weighted unit normals.
  Mesh Subdivide(const Mesh& coarse) const;
  // The coarse mesh of a frame as given, at the same fine vertices (ApplyLinearSubdivision): the
  // user's surface, which the baselines of an evaluation are measured on.
  Mesh Interpolate(const Mesh& coarse) const;
  int num_fine_vertices() const { return stencil_.num_fine_vertices(); }
  // Fine vertex ids to refine: the subdivided mask (all when there is none). Those that no camera
  // saw in the reference frame get no surface Gaussian.
  const std::vector<int>& refined_vertices() const { return refined_vertices_; }
  const VertexNeighbourhoods& neighbourhoods() const { return neighbourhoods_; }
  // The fine vertices that subdivision makes from coarse vertices `coarse_ids` (an edge vertex
  // belongs when both its ends do). Empty in, empty out.
  std::vector<int> SubdivideIds(const std::vector<int>& coarse_ids) const;

 private:
  SubdivisionStencil stencil_;
  int num_coarse_vertices_ = 0;
  std::vector<int> refined_vertices_;
  VertexNeighbourhoods neighbourhoods_;
};

// The ground truth of a frame at the fine vertices, measured along the unit normals of its
// subdivided mesh (the lines the refinement moves the vertices on). Both vectors are empty when
// the capture has no true surface for the frame.
struct FineGroundTruth {
  // Per fine vertex: the signed distance from the subdivided mesh to the true surface, the true
  // k; NaN where the line misses it.
  Eigen::VectorXd k_true;
  // Per fine vertex: the signed distance from the coarse mesh as given, at the vertex
  // (SequenceModel::Interpolate), along the same normal to the true surface; NaN on a miss. The
  // error of the input as its user gave it, which subdivision may lessen or add to.
  Eigen::VectorXd coarse_error;

  bool empty() const { return k_true.size() == 0; }
};

// For each camera, which fine vertices of `mesh` (with `normals`) it sees: within
// options.max_view_angle_deg, and for a vertex that fewer than `wanted_cameras` see there, the
// most frontal others within options.fallback_view_angle_deg until it has that many
// (KeepFrontalViews; 0: none). With `masks` (one per camera, as FrameInput::masks) a vertex whose
// nearest pixel is background is not seen.
std::vector<std::vector<unsigned char>> ComputeFrameVisibility(
    const Mesh& mesh, const Eigen::Matrix3Xd& normals, const std::vector<Camera>& cameras,
    const VisibilityOptions& options, int wanted_cameras, const std::vector<cv::Mat>& masks = {});

// The cameras a refined vertex needs under `options`: the consensus similarity compares the
// cameras that see a patch with each other and needs energy.consensus.min_cameras of them; the
// others compare each camera with reference colours and need one. The vertex's view confidence
// (ViewConfidence) is that of the wanted-th most frontal camera.
int CamerasWanted(const RefineOptions& options);
// The cameras a vertex takes beyond visibility.max_view_angle_deg when it has fewer within it
// (ComputeFrameVisibility): CamerasWanted for the consensus similarity, none for the others,
// whose reference colours and comparisons are each camera's own and gain nothing from a steep
// view.
int FallbackCamerasWanted(const RefineOptions& options);

// The colours of the fine vertices, from the reference frame's images at its coarse surface.
ReferenceColors ComputeSequenceColors(const SequenceModel& model, const FrameInput& reference,
                                      const RefineOptions& options);

// The colours of the vertices of `fine` (a frame's fine mesh, e.g. its refined surface), from
// that frame's images, as ComputeSequenceColors takes them: visibility, camera and method by
// `options`.
ReferenceColors ComputeSurfaceColors(const Mesh& fine, const FrameInput& frame,
                                     const RefineOptions& options);

// A frame made ready to solve: its fine mesh, the image Gaussians and the energy over them.
struct PreparedFrame {
  Mesh fine;                 // The subdivided input mesh.
  Eigen::Matrix3Xd normals;  // Its unit normals, along which k displaces.
  // Per camera, which vertices of `fine` it sees by the geometry alone, whatever the masks say
  // (ComputeFrameVisibility).
  std::vector<std::vector<unsigned char>> visible;
  // One per camera, while the energy refers to them: none once it is built when no data term
  // reads a pair list after (FrameEnergy::ReadsPairLists; the consensus similarity's tables
  // hold what it needs), which spares a frame's image models (~7 MB on synth_skirt) while it is
  // solved and while the next one waits.
  std::vector<ImageGaussians> images;
  std::unique_ptr<FrameEnergy> energy;  // Over the surface Gaussians of the refined vertices.
  // The plane sweep's start over `energy` (SweepInitialization), when it was found ahead of the
  // solve (PrepareFrameAhead); empty otherwise.
  Eigen::VectorXd sweep_start;
  // The range of `energy`'s displacements: EnergyOptions::k_max, or wider where the plane sweep
  // found it limiting (SweepOptions::widen_share).
  double k_max = 0.0;
  long num_image_gaussians = 0;
  double seconds = 0.0;  // The preparation's, the sweep's included.
  // The largest shift of a camera's principal point that the detail stage's alignment made
  // (CameraAlignmentOptions), pixels; NaN before the detail stage or without the alignment.
  double camera_shift = std::numeric_limits<double>::quiet_NaN();
};

// Subdivision, visibility, image Gaussians, surface Gaussians and pair lists of one frame.
PreparedFrame PrepareFrame(const SequenceModel& model, const ReferenceColors& colors,
                           const FrameInput& input, const RefineOptions& options);

// Replaces the energy of a prepared frame, solved to `found` (one k per surface Gaussian), by the
// one that reads the input's images at their own resolution over the same surface Gaussians
// (ConsensusOptions::sample_spacing): the detail stage RefineFrame solves last. Its cameras are
// those that see the surface found, smoothed as its patches' shape will be, within
// VisibilityOptions::sample_view_angle_deg, and it reads them aligned with each other at that
// surface (CameraAlignmentOptions; the shift in PreparedFrame::camera_shift). Its patches start
// unshaped, until it is handed the surface solved before (FrameEnergy::EndOfPass). The frame's
// energy may be a detail stage's already: the next pass's is then prepared at the surface the
// pass found (RefineOptions::views_follow_surface), from the same surface Gaussians. Throws Error
// unless `found` has one entry per surface Gaussian.
void PrepareDetailEnergy(const SequenceModel& model, const FrameInput& input,
                         const RefineOptions& options, const Eigen::VectorXd& found,
                         PreparedFrame* frame);

// PrepareFrame at the level RefineFrame solves last, with the plane sweep's start when that level
// starts from it (no coarse-to-fine schedule): what RefineFrame does to a frame before it solves
// and what does not depend on any other frame, so that a sequence can do it while the frame before
// is solved. The prepared frame takes the input's image models (modelled now if they are not):
// `*input` is left without them. Hand the result to RefineFrame or RefineFrameFrom with the same
// input, colours and options.
PreparedFrame PrepareFrameAhead(const SequenceModel& model, const ReferenceColors& colors,
                                FrameInput* input, const RefineOptions& options);

// Whether RefineFrame, handed PrepareFrameAhead's preparation of a frame, still reads the input's
// images: only the coarser levels of a coarse-to-fine schedule model them afresh. When it does
// not, a caller with no other use for them may release them once the frame is prepared.
bool ReadsImagesAfterPreparation(const RefineOptions& options);

struct FrameResult {
  Mesh refined;              // The fine mesh with the displacement applied.
  Eigen::Matrix3Xd normals;  // Unit normals of `refined`.
  Eigen::VectorXd k;         // Per fine vertex, metres (bias included); NaN where not refined.
  Eigen::VectorXd k_solved;  // Per surface Gaussian, as solved (for warm starts).
  // Per fine vertex, in [0, 1]: how surely the training images decide its displacement
  // (FrameEnergy::confidence: the views that see it, the texture around it); NaN where not
  // refined. The confidence pull holds a vertex near its input where this is low.
  Eigen::VectorXd confidence;
  // With energy.consensus.shared_appearance: the colour each surface sample shows at the refined
  // surface (FrameEnergy::SampleAppearance), which the frame after compares its patches with.
  Eigen::Matrix3Xd appearance;
  SolverSummary summary;
  bool worse = false;       // The solve ended with a lower energy than it started from.
  bool kept_input = false;  // The input surface was written instead (keep_input_if_worse, or no
                            // camera sees any refined vertex).
  int num_surface_gaussians = 0;
  double k_max = 0.0;  // The range it was solved in (PreparedFrame::k_max), metres.
  long num_image_gaussians = 0;
  long num_pairs = 0;
  double seconds_preparation = 0.0;  // Subdivision, visibility, image Gaussians, pair lists.
  bool prepared_ahead = false;       // The configured level was prepared ahead (`ahead`).
  double seconds_total = 0.0;        // The whole frame.
  double camera_shift = std::numeric_limits<double>::quiet_NaN();  // PreparedFrame's.
};

// The rings of the refined mesh a consensus patch reaches: energy.consensus.patch_rings counts
// edges of the input subdivided once, so at subdivision_levels L >= 1 a patch reaches
// patch_rings * 2^(L - 1) edges (at most ConsensusOptions::kMaxPatchRings) and covers the same
// surface at every level while the unknowns get finer: a patch of half the width holds a quarter
// of the pixels, and its comparison of the cameras grows noisier than the finer unknowns gain
// (Sceaux at level 2: held-out NCC 0.833 with one ring, 0.839 with two, 0.836 at level 1).
int PatchRingsAt(const RefineOptions& options);

// Rounds of neighbour averaging at the configured subdivision level that reach as far over the
// surface as `rounds` rounds on the input subdivided once: an average's reach grows as the square
// root of its rounds, so each further level, whose edges are half as long, takes four times as
// many. The smoothings of a refinement count their rounds so (the consensus patches' shape, the
// plane sweep's costs, the detail stage's cameras), as the patches count their rings.
int SmoothingRoundsAt(const RefineOptions& options, int rounds);

// The widest search range a frame may take, metres: the plane sweep doubles energy.k_max while
// the range limits it (SweepOptions::widen_share), at most SweepOptions::max_widenings times and
// to EnergyOptions::kLargestKMax; energy.k_max where the sweep does not widen.
double WidestSearchRange(const RefineOptions& options);

// A vertex whose confidence (FrameResult::confidence) is at least this is refined with
// confidence: the images decide it more than the pull towards the input does.
constexpr double kConfidentAt = 0.5;

// The share of the refined vertices of `result` refined with confidence (FrameResult::confidence
// at least kConfidentAt), in [0, 1]; NaN when none was refined.
double ConfidentShare(const FrameResult& result);

// What bias compensation adds along the normal to every solved displacement of a frame that was
// refined: sigma_hat with RefineOptions::bias_compensation, else 0. A kept input gets nothing.
double BiasCompensation(const RefineOptions& options);

// The one rule that takes a frame's written displacement (FrameResult::k, or its saved k/ file)
// back to where its solve ended, per fine vertex: k minus the bias compensation, except for a frame
// whose input was kept (`kept_input`), whose 0 is the input surface as the solver would start it.
// NaN stays NaN. This is what seeds the next frame (warm start) and where a result's energy is
// measured.
Eigen::VectorXd SolvedDisplacement(const Eigen::VectorXd& k, bool kept_input,
                                   const RefineOptions& options);

// Puts the input surface back into `result` (its refined mesh, normals and k, which becomes 0
// wherever it was refined) and sets kept_input, for a frame that another measure than the energy
// found worse; its appearance, which was the refined surface's, is dropped, so the frame after
// compares its patches with none. `fine_input` is the frame's subdivided input mesh.
void KeepInputSurface(const Mesh& fine_input, FrameResult* result);

// Where the solve of `frame` starts: `warm_start` when given and of the right size, else the
// plane sweep's result (zero when the sweep is off), found now unless the frame carries it.
Eigen::VectorXd StartingPoint(PreparedFrame* frame, const SweepOptions& sweep,
                              const Eigen::VectorXd* warm_start);

// Refines one frame, through the coarse-to-fine levels when configured. `warm_start` (may be
// null) is a previous frame's k_solved. `ahead`, when not empty, is PrepareFrameAhead's
// preparation of this very frame (input, colours and options), used instead of preparing again.
// `workspace` (may be null) carries the solver's problem from frame to frame (SolverWorkspace):
// a sequence hands every frame the same one.
FrameResult RefineFrame(const SequenceModel& model, const ReferenceColors& colors,
                        const FrameInput& input, const RefineOptions& options,
                        const Eigen::VectorXd* warm_start = nullptr, PreparedFrame ahead = {},
                        SolverWorkspace* workspace = nullptr);

// RefineFrame, starting from `start`: one displacement per fine vertex, metres, as solved
// (before bias compensation); NaN where there is none, and those vertices start where RefineFrame
// would start them (at zero, or where the plane sweep puts them). This is how a frame is seeded
// from another frame's saved result: a fine vertex keeps its id over the sequence, while the
// surface Gaussians of two frames may differ. Throws Error when `start` has not one entry per
// fine vertex. `ahead` and `workspace` as for RefineFrame.
FrameResult RefineFrameFrom(const SequenceModel& model, const ReferenceColors& colors,
                            const FrameInput& input, const RefineOptions& options,
                            const Eigen::VectorXd& start, PreparedFrame ahead = {},
                            SolverWorkspace* workspace = nullptr);

}  // namespace finecap

#endif  // FINECAP_REFINE_REFINE_H_
