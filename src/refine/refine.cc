#include "finecap/refine/refine.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <utility>

#include "finecap/energy/frame_energy.h"
#include "finecap/energy/similarity_needs.h"
#include "finecap/geometry/render.h"
#include "finecap/solvers/sweep.h"
#include "finecap/util/error.h"
#include "refine/camera_alignment.h"
#include "refine/foreground.h"
#include "refine/surface_sampling.h"

namespace finecap {
namespace {

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::vector<int> FineMaskIds(const SubdivisionStencil& stencil, const std::vector<int>& coarse_mask,
                             int num_coarse_vertices) {
  std::vector<int> ids;
  if (coarse_mask.empty()) {
    for (int v = 0; v < stencil.num_fine_vertices(); ++v) ids.push_back(v);
    return ids;
  }
  std::vector<bool> coarse(num_coarse_vertices, false);
  for (int v : coarse_mask) coarse[v] = true;
  const std::vector<bool> fine = SubdivideVertexMask(stencil, coarse);
  for (int v = 0; v < static_cast<int>(fine.size()); ++v) {
    if (fine[v]) ids.push_back(v);
  }
  return ids;
}

// Whether a frame is solved a second time with the images read at their own resolution.
bool UsesSurfaceSamples(const RefineOptions& options) {
  return NeedsOf(options.energy).reads_surface_samples;
}

// Pixels about a surface sample (at its nearest pixel) that its reads take colour from: the
// bilinear read's next pixel and the blur's reach (two standard deviations), so that a sample
// kept on the shrunk mask does not read the black painted on the background.
int SampleReach(const ConsensusOptions& consensus) {
  return 1 + static_cast<int>(std::ceil(2.0 * consensus.sample_blur));
}

// The energy's options with the patch's rings and its shape's smoothing counted on the refined
// mesh (PatchRingsAt, SmoothingRoundsAt).
EnergyOptions EnergyOptionsAt(const RefineOptions& options) {
  EnergyOptions energy = options.energy;
  energy.consensus.patch_rings = PatchRingsAt(options);
  energy.consensus.shape_smoothing_rounds =
      SmoothingRoundsAt(options, energy.consensus.shape_smoothing_rounds);
  return energy;
}

// The plane sweep's options with its costs' smoothing counted on the refined mesh.
SweepOptions SweepOptionsAt(const RefineOptions& options) {
  SweepOptions sweep = options.sweep;
  sweep.smoothing_rounds = SmoothingRoundsAt(options, sweep.smoothing_rounds);
  return sweep;
}

const RefineOptions& Checked(const RefineOptions& options) {
  options.Check();
  return options;
}

bool SameImageModel(const ImageGaussianOptions& a, const ImageGaussianOptions& b) {
  return a.color_space == b.color_space && a.max_depth == b.max_depth &&
         a.min_leaf_size == b.min_leaf_size && a.split_threshold == b.split_threshold;
}

bool HasImageModels(const FrameInput& input, const ImageGaussianOptions& options) {
  return input.image_models.size() == input.images.size() &&
         SameImageModel(input.image_model_options, options);
}

std::vector<ImageGaussians> BuildImageModels(const FrameInput& input,
                                             const ImageGaussianOptions& options) {
  std::vector<std::string> names;
  for (const Camera& camera : input.cameras) names.push_back(camera.name);
  return BuildFrameImageGaussians(input.images, input.masks, options, names);
}

}  // namespace

void ModelFrameImages(const ImageGaussianOptions& options, FrameInput* input) {
  if (HasImageModels(*input, options)) return;
  input->image_models = BuildImageModels(*input, options);
  input->image_model_options = options;
}

std::vector<ImageGaussians> FrameImageModels(const FrameInput& input,
                                             const ImageGaussianOptions& options) {
  if (HasImageModels(input, options)) return input.image_models;
  return BuildImageModels(input, options);
}

SequenceModel::SequenceModel(const Mesh& first_coarse, const std::vector<int>& coarse_mask,
                             const RefineOptions& options, const std::string& where)
    : stencil_(BuildSubdivision(Checked(options).subdivision, first_coarse,
                                options.subdivision_levels, where)),
      num_coarse_vertices_(first_coarse.num_vertices()) {
  refined_vertices_ = FineMaskIds(stencil_, coarse_mask, num_coarse_vertices_);
  const Mesh fine = ApplySubdivision(stencil_, first_coarse.vertices);
  // Far enough for the regulariser and for the widest patch.
  neighbourhoods_ = BuildVertexNeighbourhoods(
      fine, std::max(options.energy.reg_rings, PatchRingsAt(options)), where);
}

std::vector<int> SequenceModel::SubdivideIds(const std::vector<int>& coarse_ids) const {
  if (coarse_ids.empty()) return {};
  return FineMaskIds(stencil_, coarse_ids, num_coarse_vertices_);
}

Mesh SequenceModel::Subdivide(const Mesh& coarse) const {
  return ApplySubdivision(stencil_, coarse.vertices);
}

Mesh SequenceModel::Interpolate(const Mesh& coarse) const {
  return ApplyLinearSubdivision(stencil_, coarse.vertices);
}

std::vector<std::vector<unsigned char>> ComputeFrameVisibility(
    const Mesh& mesh, const Eigen::Matrix3Xd& normals, const std::vector<Camera>& cameras,
    const VisibilityOptions& options, int wanted_cameras, const std::vector<cv::Mat>& masks) {
  Require(masks.empty() || masks.size() == cameras.size(), "ComputeFrameVisibility",
          "one mask per camera, or none, expected");
  VisibilityOptions widest = options;
  if (wanted_cameras > 0) widest.max_view_angle_deg = options.fallback_view_angle_deg;
  std::vector<std::vector<unsigned char>> visible(cameras.size());
  for (size_t c = 0; c < cameras.size(); ++c) {
    const DepthMap depth = RenderDepth(cameras[c], mesh);
    visible[c] = ComputeVisibility(cameras[c], depth.depth, mesh.vertices, normals, widest);
    if (!masks.empty()) KeepForeground(cameras[c], masks[c], mesh.vertices, 0, &visible[c]);
  }
  if (wanted_cameras > 0) {
    KeepFrontalViews(cameras, mesh.vertices, normals, wanted_cameras, options, &visible);
  }
  return visible;
}

int CamerasWanted(const RefineOptions& options) {
  return NeedsOf(options.energy).cameras_per_gaussian;
}

int FallbackCamerasWanted(const RefineOptions& options) {
  const SimilarityNeeds needs = NeedsOf(options.energy);
  return needs.takes_fallback_views ? needs.cameras_per_gaussian : 0;
}

ReferenceColors ComputeSequenceColors(const SequenceModel& model, const FrameInput& reference,
                                      const RefineOptions& options) {
  return ComputeSurfaceColors(model.Subdivide(reference.coarse), reference, options);
}

ReferenceColors ComputeSurfaceColors(const Mesh& fine, const FrameInput& frame,
                                     const RefineOptions& options) {
  options.Check();
  const Eigen::Matrix3Xd normals = ComputeVertexNormals(fine);
  const auto visible = ComputeFrameVisibility(fine, normals, frame.cameras, options.visibility,
                                              FallbackCamerasWanted(options), frame.masks);
  if (options.reference_colors == ReferenceColorSource::kImageModel) {
    const std::vector<ImageGaussians> images = FrameImageModels(frame, options.image);
    return ComputeModelReferenceColors(fine.vertices, normals, frame.cameras, images, visible,
                                       options.sigma_hat, options.energy.overlap,
                                       options.energy.reach_sigmas);
  }
  return ComputeReferenceColors(fine.vertices, normals, frame.cameras, ForegroundImages(frame),
                                visible, options.image.color_space, options.sigma_hat);
}

namespace {

// Where the input as given (its faces, SequenceModel::Interpolate) lies from each of the fine
// vertices `ids` of its subdivision `fine`, along their `normals`, metres.
std::vector<double> InputOffsets(const SequenceModel& model, const Mesh& coarse, const Mesh& fine,
                                 const Eigen::Matrix3Xd& normals, const std::vector<int>& ids) {
  const Mesh as_given = model.Interpolate(coarse);
  std::vector<double> offsets;
  offsets.reserve(ids.size());
  for (int v : ids) {
    offsets.push_back((as_given.vertices.col(v) - fine.vertices.col(v)).dot(normals.col(v)));
  }
  return offsets;
}

// The search range a frame widens to from `k_max` (BuildSweptEnergy, WidestSearchRange).
double WidenedRange(double k_max) { return std::min(2.0 * k_max, EnergyOptions::kLargestKMax); }

// The range a frame's sweep `start` over `k_max` asks for next (SweepOptions::widen_share,
// narrow_share), or k_max itself when the range stands: twice as wide while the range limits it,
// or the narrowest of its halvings, down to `sigma_hat`, whose half holds the sweep's reach. A
// range widens at most sweep.max_widenings times, and one that widened never narrows (nor the
// other way round), so that the search ends. `changes`: the range's changes so far, positive
// when it widened.
double NextRange(const SweepResult& start, double k_max, double sigma_hat, int changes,
                 const SweepOptions& sweep) {
  const bool limited = sweep.widen_share > 0.0 && start.share_at_ends > sweep.widen_share &&
                       changes >= 0 && changes < sweep.max_widenings &&
                       k_max < EnergyOptions::kLargestKMax;
  if (limited) return WidenedRange(k_max);
  if (sweep.narrow_share == 0.0 || changes > 0) return k_max;
  double range = k_max;
  while (0.5 * range >= sigma_hat && start.reach <= 0.5 * range) range *= 0.5;
  return range;
}

// Puts back at the input (k = 0) the start of every surface Gaussian of `surface` that at most
// two of `cameras` see within visibility.max_view_angle_deg and whose sweep costs single out none
// of its displacements (SweepOptions::min_uniqueness).
void StartAmbiguousTwoViewGaussiansAtInput(const SurfaceGaussians& surface,
                                           const std::vector<CameraInput>& cameras,
                                           const RefineOptions& options, SweepResult* start) {
  if (options.sweep.min_uniqueness == 0.0 || start->uniqueness.size() != surface.size()) return;
  const double min_cosine = std::cos(options.visibility.max_view_angle_deg * M_PI / 180.0);
  for (int s = 0; s < surface.size(); ++s) {
    if (!(start->uniqueness[s] < options.sweep.min_uniqueness)) continue;
    int frontal = 0;
    for (const CameraInput& camera : cameras) {
      frontal +=
          camera.visible[s] != 0 &&
          camera.camera.ViewCosine(surface.base.col(s), surface.normals.col(s)) >= min_cosine;
    }
    if (frontal <= 2) start->k[s] = 0.0;
  }
}

// Builds the energy of `surface` over `cameras` and, when `sweep`, finds the plane sweep's start
// (frame->sweep_start), building the energy again over a wider or a narrower range while the
// sweep says that the range limits it or is far wider than its Gaussians need (NextRange).
// frame->k_max is the range used.
void BuildSweptEnergy(const SequenceModel& model, const SurfaceGaussians& surface,
                      const std::vector<CameraInput>& cameras, const RefineOptions& options,
                      bool sweep, PreparedFrame* frame) {
  EnergyOptions energy = EnergyOptionsAt(options);
  for (int changes = 0;;) {
    frame->energy.reset();  // The last range's energy is not needed while the next is built.
    frame->energy = std::make_unique<FrameEnergy>(surface, cameras, model.neighbourhoods(), energy);
    frame->k_max = energy.k_max;
    if (!sweep) return;
    SweepResult start = Sweep(frame->energy.get(), SweepOptionsAt(options));
    const double next = NextRange(start, energy.k_max, surface.sigma_hat, changes, options.sweep);
    if (next == energy.k_max) {
      StartAmbiguousTwoViewGaussiansAtInput(surface, cameras, options, &start);
      frame->sweep_start = std::move(start.k);
      return;
    }
    changes += next > energy.k_max ? 1 : -1;
    energy.k_max = next;
  }
}

// PrepareFrame without checking `options`, over the image models `images` of the input's images
// under options.image: the coarse levels of a schedule widen sigma_hat and the leaves past the
// ranges that a configured value must lie in. With `sweep`, also the plane sweep's start.
PreparedFrame PrepareLevel(const SequenceModel& model, const ReferenceColors& colors,
                           const FrameInput& input, const RefineOptions& options,
                           std::vector<ImageGaussians> images, bool sweep) {
  const auto start = std::chrono::steady_clock::now();
  PreparedFrame frame;
  frame.fine = model.Subdivide(input.coarse);
  frame.normals = ComputeVertexNormals(frame.fine);
  // Which cameras see each vertex by the geometry alone: where the input is off by a few pixels
  // at a silhouette its vertex falls on the background, yet the surface it stands for is seen,
  // so the detail stage (whose samples each meet the masks where they read) and the confidence
  // start from this. The image-model stage compares each surface Gaussian where its vertex
  // projects, so there a camera sees a vertex only on its foreground (FrameInput).
  frame.visible = ComputeFrameVisibility(frame.fine, frame.normals, input.cameras,
                                         options.visibility, FallbackCamerasWanted(options));
  std::vector<std::vector<unsigned char>> visible = frame.visible;
  for (size_t c = 0; c < input.masks.size(); ++c) {
    KeepForeground(input.cameras[c], input.masks[c], frame.fine.vertices, 0, &visible[c]);
  }
  frame.images = std::move(images);

  // The consensus similarity compares the cameras of this frame with each other; the colours
  // its surface Gaussians carry (for the plain-cloth prior and the sweep's fallback) are this
  // frame's own, taken as the reference frame's are, so no frame depends on another's surface.
  const ReferenceColors frame_colors =
      NeedsOf(options.energy).colors_of_each_frame
          ? ComputeModelReferenceColors(frame.fine.vertices, frame.normals, input.cameras,
                                        frame.images, visible, options.sigma_hat,
                                        options.energy.overlap, options.energy.reach_sigmas)
          : colors;
  SurfaceGaussians surface = MakeSurfaceGaussians(frame.fine.vertices, frame.normals,
                                                  model.refined_vertices(), frame_colors);
  const std::vector<float> view_confidence =
      ViewConfidence(input.cameras, frame.fine.vertices, frame.normals, CamerasWanted(options),
                     options.visibility, frame.visible);
  for (int v : surface.vertex_ids) surface.view_confidence.push_back(view_confidence[v]);
  surface.input_offset =
      InputOffsets(model, input.coarse, frame.fine, frame.normals, surface.vertex_ids);
  std::vector<CameraInput> cameras(input.cameras.size());
  for (size_t c = 0; c < cameras.size(); ++c) {
    cameras[c].camera = input.cameras[c];
    cameras[c].image = &frame.images[c];
    for (int v : surface.vertex_ids) cameras[c].visible.push_back(visible[c][v]);
    frame.num_image_gaussians += frame.images[c].size();
  }
  BuildSweptEnergy(model, surface, cameras, options, sweep && options.sweep.samples > 0, &frame);
  if (!frame.energy->ReadsPairLists()) std::vector<ImageGaussians>().swap(frame.images);
  frame.seconds = SecondsSince(start);
  return frame;
}

}  // namespace

PreparedFrame PrepareFrame(const SequenceModel& model, const ReferenceColors& colors,
                           const FrameInput& input, const RefineOptions& options) {
  options.Check();
  return PrepareLevel(model, colors, input, options, FrameImageModels(input, options.image),
                      /*sweep=*/false);
}

PreparedFrame PrepareFrameAhead(const SequenceModel& model, const ReferenceColors& colors,
                                FrameInput* input, const RefineOptions& options) {
  options.Check();
  const auto start = std::chrono::steady_clock::now();
  ModelFrameImages(options.image, input);
  PreparedFrame frame =
      PrepareLevel(model, colors, *input, options, std::exchange(input->image_models, {}),
                   /*sweep=*/options.coarse_to_fine.levels == 1);
  frame.seconds = SecondsSince(start);
  return frame;
}

namespace {

// The surface the detail stage starts from: `frame.fine` displaced by the surface Gaussians'
// `found`, smoothed as the patches' shape will be at level 1 (PatchAgreementTerm::EndOfPass),
// over the same reach at finer levels.
Mesh FoundSurface(const PreparedFrame& frame, const Eigen::VectorXd& found,
                  const RefineOptions& options) {
  const FrameEnergy& energy = *frame.energy;
  Eigen::MatrixXd shape = found;
  energy.regularizer().AverageOverNeighbours(
      SmoothingRoundsAt(options, options.energy.consensus.shape_smoothing_rounds), &shape);
  Mesh surface = frame.fine;
  const std::vector<int>& ids = energy.surface().vertex_ids;
  for (size_t s = 0; s < ids.size(); ++s) {
    surface.vertices.col(ids[s]) += shape(s, 0) * frame.normals.col(ids[s]);
  }
  return surface;
}

// Per camera, which vertices of `frame.fine` the detail stage reads it for: the cameras that see
// `surface` (FoundSurface; `normals` its vertex normals) within
// VisibilityOptions::sample_view_angle_deg of its normals, by the geometry alone, and the
// cameras that see the input surface most frontally.
std::vector<std::vector<unsigned char>> DetailVisibility(const PreparedFrame& frame,
                                                         const Mesh& surface,
                                                         const Eigen::Matrix3Xd& normals,
                                                         const FrameInput& input,
                                                         const RefineOptions& options) {
  VisibilityOptions visibility = options.visibility;
  visibility.max_view_angle_deg = visibility.sample_view_angle_deg;
  visibility.fallback_view_angle_deg =
      std::max(visibility.fallback_view_angle_deg, visibility.sample_view_angle_deg);
  const int wanted = FallbackCamerasWanted(options);
  std::vector<std::vector<unsigned char>> visible =
      ComputeFrameVisibility(surface, normals, input.cameras, visibility, wanted);
  // Where the input is far off (a visual hull) the found surface's normals, even smoothed, carry
  // the first stage's noise and may turn a patch away from the views that see it best; the views
  // that see the input surface most frontally are read as well (the temple: 0.654 -> 0.688
  // held out, docs/measurements.md).
  std::vector<std::vector<unsigned char>> frontal = frame.visible;
  KeepMostFrontalViews(input.cameras, frame.fine.vertices, frame.normals, wanted, &frontal);
  for (size_t c = 0; c < visible.size(); ++c) {
    for (size_t v = 0; v < visible[c].size(); ++v) visible[c][v] |= frontal[c][v];
  }
  return visible;
}

// Per vertex of `ids`, the cosine of the angle between `camera`'s view ray to it and its normal.
std::vector<double> ViewCosines(const Camera& camera, const Eigen::Matrix3Xd& vertices,
                                const Eigen::Matrix3Xd& normals, const std::vector<int>& ids) {
  std::vector<double> cosines;
  cosines.reserve(ids.size());
  for (int v : ids) cosines.push_back(camera.ViewCosine(vertices.col(v), normals.col(v)));
  return cosines;
}

// Aligns `cameras` with each other (AlignCameras) at the samples moved to the surface `found`
// (one k per surface Gaussian); the largest shift of a camera, pixels.
double AlignAtFoundSurface(const SurfaceSamples& samples, const Eigen::VectorXd& found,
                           int max_rounds, std::vector<CameraInput>* cameras) {
  Eigen::Matrix3Xd points = samples.base;
  const Eigen::VectorXd displacement = samples.weights * found;
  for (int j = 0; j < samples.size(); ++j) {
    points.col(j) += displacement[j] * samples.normals.col(j);
  }
  double largest = 0.0;
  for (const Eigen::Vector2d& shift : AlignCameras(points, max_rounds, cameras)) {
    largest = std::max(largest, shift.norm());
  }
  return largest;
}

// What the detail stage reads that does not depend on the surface found (SampledInput): taken
// from the frame's energy when that is a detail stage's already, over the same surface Gaussians
// `surface`, made otherwise. The frame's energy is gone after: its pair lists and tables are not
// needed any more.
SampledInput DetailStageInput(const SequenceModel& model, const FrameInput& input,
                              const RefineOptions& options, const SurfaceGaussians& surface,
                              PreparedFrame* frame) {
  SampledInput sampled = FrameEnergy::TakeSampledInput(std::move(frame->energy));
  if (sampled.samples.size() > 0) return sampled;
  const ConsensusOptions& consensus = options.energy.consensus;
  const int segments = SampleSegments(frame->fine, input.cameras, consensus.sample_spacing);
  sampled.samples = SampleSurface(frame->fine, frame->normals, surface, model.neighbourhoods(),
                                  PatchRingsAt(options), segments);
  sampled.pixels = SampledImages(input, options.image.color_space, consensus.sample_blur);
  sampled.samples_on_foreground.resize(input.cameras.size());
  for (size_t c = 0; c < input.masks.size(); ++c) {
    sampled.samples_on_foreground[c].assign(sampled.samples.size(), 1);
    KeepForeground(input.cameras[c], input.masks[c], sampled.samples.base, SampleReach(consensus),
                   &sampled.samples_on_foreground[c]);
  }
  return sampled;
}

}  // namespace

void PrepareDetailEnergy(const SequenceModel& model, const FrameInput& input,
                         const RefineOptions& options, const Eigen::VectorXd& found,
                         PreparedFrame* frame) {
  const auto start = std::chrono::steady_clock::now();
  const ConsensusOptions& consensus = options.energy.consensus;
  Require(found.size() == frame->energy->num_parameters(), "PrepareDetailEnergy",
          "one displacement per surface Gaussian expected");
  const Mesh found_surface = FoundSurface(*frame, found, options);
  const Eigen::Matrix3Xd found_normals = ComputeVertexNormals(found_surface);
  const std::vector<std::vector<unsigned char>> visible =
      DetailVisibility(*frame, found_surface, found_normals, input, options);
  SurfaceGaussians surface = frame->energy->surface();
  SampledInput sampled = DetailStageInput(model, input, options, surface, frame);
  SurfaceSamples& samples = sampled.samples;
  if (consensus.shared_appearance && input.frame_before_appearance.cols() == samples.size()) {
    samples.appearance = input.frame_before_appearance;
  }
  std::vector<CameraInput> cameras(input.cameras.size());
  for (size_t c = 0; c < cameras.size(); ++c) {
    cameras[c].camera = input.cameras[c];
    for (int v : surface.vertex_ids) cameras[c].visible.push_back(visible[c][v]);
    cameras[c].samples_visible = SampleVisibility(samples, cameras[c].visible);
    if (consensus.view_cosine_power != 0.0) {
      cameras[c].view_cosines =
          ViewCosines(input.cameras[c], found_surface.vertices, found_normals, surface.vertex_ids);
    }
    cameras[c].samples_on_foreground = std::move(sampled.samples_on_foreground[c]);
    cameras[c].pixels = sampled.pixels[c];
  }
  if (options.camera_alignment.max_rounds > 0) {
    frame->camera_shift =
        AlignAtFoundSurface(samples, found, options.camera_alignment.max_rounds, &cameras);
  }
  EnergyOptions energy = EnergyOptionsAt(options);
  energy.k_max = frame->k_max;  // The range the surface Gaussians' stage was solved in.
  frame->energy = std::make_unique<FrameEnergy>(std::move(surface), cameras, model.neighbourhoods(),
                                                energy, std::move(samples));
  frame->seconds += SecondsSince(start);
}

bool ReadsImagesAfterPreparation(const RefineOptions& options) {
  return options.coarse_to_fine.levels > 1 || UsesSurfaceSamples(options);
}

namespace {

// Adds the summary of pass `pass` of a frame's solve to that of the passes before it.
void AddPass(const SolverSummary& more, int pass, SolverSummary* summary) {
  if (pass == 0) {
    *summary = more;
    return;
  }
  summary->energy_end = more.energy_end;
  summary->ls_cost_end = more.ls_cost_end;
  summary->AddWork(more);
  summary->termination = more.termination;
  summary->trace.insert(summary->trace.end(), more.trace.begin(), more.trace.end());
}

// Solve, and for an energy whose terms change between passes (PassHook: the consensus' patches
// shaped like the surface found so far) the further passes, the last with the terms that only it
// needs (FrameEnergy::StartLastPass). With `measure_ends`, the summary's start values are those
// of the last pass's energy at `*k`'s start, so that `worse` compares the frame by the energy it
// ended with; without, a caller that only adds up the work or measures the ends itself saves the
// two evaluations (a detail stage's cost as much as a solver's step).
SolverSummary SolveFrameEnergy(FrameEnergy* energy, const RefineOptions& options,
                               Eigen::VectorXd* k, bool measure_ends,
                               SolverWorkspace* workspace = nullptr) {
  const int passes = energy->HasPassHooks() ? options.energy.consensus.passes : 1;
  const Eigen::VectorXd start = *k;
  // One Ceres problem for the passes, built anew only when the last pass adds terms.
  FrameSolver solver(energy, options.solver, workspace);
  SolverSummary summary;
  for (int pass = 0; pass < passes; ++pass) {
    if (pass > 0) energy->EndOfPass(*k);
    if (pass == passes - 1) energy->StartLastPass();
    AddPass(solver.Solve(k), pass, &summary);
  }
  if (passes > 1 && measure_ends) {
    // Both ends by the same sum: the solver's own (Ceres') may differ from it in the last digit.
    EvaluateEnergyAndCost(energy, start, &summary.energy_start, &summary.ls_cost_start);
    EvaluateEnergyAndCost(energy, *k, &summary.energy_end, &summary.ls_cost_end);
  }
  return summary;
}

// Hands the frame before's solution (FrameInput::frame_before_k), when there is one, to the terms
// of `energy` that read it.
void TakeTheFrameBefore(const FrameInput& input, FrameEnergy* energy) {
  if (input.frame_before_k.size() == 0) return;
  energy->TakeFrameBefore(energy->UnknownsAtVertices(input.frame_before_k));
}

// Where the detail stage's first pass starts when the surface Gaussians' stage ended at `k`: the
// best displacement nearby at the images' own resolution (SweepAround), or `k` with the sweep off
// or no iteration asked for (a solve of none moves nothing).
Eigen::VectorXd DetailSweep(const RefineOptions& options, FrameEnergy* energy,
                            const Eigen::VectorXd& k) {
  const SweepOptions& sweep = options.sweep;
  if (sweep.samples == 0 || sweep.detail_range_sigmas <= 0.0 || options.solver.max_iterations == 0)
    return k;
  const double sigma_hat = energy->surface().sigma_hat;
  return SweepAround(energy, k, sweep.detail_range_sigmas * sigma_hat,
                     sweep.detail_step_sigmas * sigma_hat,
                     SmoothingRoundsAt(options, sweep.detail_smoothing_rounds));
}

// The detail stage (PrepareDetailEnergy) of `frame`, whose surface Gaussians' stage ended at
// `*k`, solved in ConsensusOptions::passes passes from there; `*k` ends where it ends. With
// RefineOptions::views_follow_surface each pass after the first is prepared anew at the surface
// the pass before ended at: which cameras see each patch, at what angle, and their alignment
// (CameraAlignmentOptions) were found at the surface Gaussians' surface, whose folds are
// shallower than the detail's and face more cameras than the detail's flanks do.
SolverSummary SolveDetailStage(const SequenceModel& model, const FrameInput& input,
                               const RefineOptions& options, PreparedFrame* frame,
                               Eigen::VectorXd* k) {
  const auto prepare_at_k = [&] {
    PrepareDetailEnergy(model, input, options, *k, frame);
    frame->energy->EndOfPass(*k);  // Its patches shaped like the surface found so far.
    TakeTheFrameBefore(input, frame->energy.get());
  };
  prepare_at_k();
  *k = DetailSweep(options, frame->energy.get(), *k);
  if (!options.views_follow_surface) {
    return SolveFrameEnergy(frame->energy.get(), options, k, /*measure_ends=*/false);
  }
  SolverSummary summary;
  for (int pass = 0; pass < options.energy.consensus.passes; ++pass) {
    if (pass > 0) prepare_at_k();
    // The refined mesh's own term joins at the last pass, as with the views fixed: in every pass
    // it recovered a little more (synth_skirt_exact 49.9 against 49.6 %), but a frame took 1.35
    // times as long as with the views fixed instead of 1.13 times.
    if (pass == options.energy.consensus.passes - 1) frame->energy->StartLastPass();
    AddPass(Solve(frame->energy.get(), options.solver, k), pass, &summary);
  }
  return summary;
}

// `k` clamped to [-k_max, k_max]: a coarser level's range may have been widened further.
Eigen::VectorXd WithinRange(const Eigen::VectorXd& k, double k_max) {
  return k.cwiseMax(-k_max).cwiseMin(k_max);
}

// Where the solve of a prepared frame starts: one k per surface Gaussian of its energy.
using StartingPointFunction = std::function<Eigen::VectorXd(PreparedFrame* frame)>;

// Level `level` of the coarse-to-fine schedule (0: the configured options): wider surface
// Gaussians and larger image Gaussians, so that the energy is smoother in k and a fold further
// than a Gaussian's width from the input surface is still within reach.
RefineOptions LevelOptions(const RefineOptions& options, int level) {
  RefineOptions level_options = options;
  const double factor = std::pow(options.coarse_to_fine.scale, level);
  level_options.sigma_hat *= factor;
  // Leaves grow with the level up to the largest an image model has.
  level_options.image.min_leaf_size =
      std::clamp(static_cast<int>(std::lround(options.image.min_leaf_size * factor)), 1,
                 ImageGaussianOptions::kMaxMinLeafSize);
  return level_options;
}

// The coarse levels of the schedule, coarsest first, each starting where the last one ended.
// Returns the k to start the configured level from; adds the work done to *totals. `sweeps`: the
// starting point is the plane sweep's (PrepareLevel).
Eigen::VectorXd SolveCoarseLevels(const SequenceModel& model, const ReferenceColors& colors,
                                  const FrameInput& input, const RefineOptions& options,
                                  const StartingPointFunction& starting_point, bool sweeps,
                                  SolverSummary* totals, double* seconds_preparation) {
  Eigen::VectorXd k;
  for (int level = options.coarse_to_fine.levels - 1; level >= 1; --level) {
    const RefineOptions level_options = LevelOptions(options, level);
    ReferenceColors level_colors = colors;
    level_colors.sigma_hat = colors.sigma_hat * level_options.sigma_hat / options.sigma_hat;
    PreparedFrame frame =
        PrepareLevel(model, level_colors, input, level_options,
                     FrameImageModels(input, level_options.image), sweeps && k.size() == 0);
    *seconds_preparation += frame.seconds;
    k = WithinRange(k.size() == 0 ? starting_point(&frame) : k, frame.k_max);
    TakeTheFrameBefore(input, frame.energy.get());
    const SolverSummary summary =
        SolveFrameEnergy(frame.energy.get(), level_options, &k, /*measure_ends=*/false);
    totals->AddWork(summary);
  }
  return k;
}

// RefineFrame, starting each level that does not continue from a coarser one at
// `starting_point`; the configured level is `ahead` when that is not empty, and is solved in
// `workspace` (the coarser levels, whose problems differ from it, in their own). `sweeps`: the
// starting point is the plane sweep's, found as a level is prepared (PrepareLevel).
FrameResult RefineFrameStartingAt(const SequenceModel& model, const ReferenceColors& colors,
                                  const FrameInput& input, const RefineOptions& options,
                                  const StartingPointFunction& starting_point, bool sweeps,
                                  PreparedFrame ahead, SolverWorkspace* workspace) {
  options.Check();
  const auto start = std::chrono::steady_clock::now();
  FrameResult result;
  SolverSummary coarse;
  const Eigen::VectorXd coarse_k = SolveCoarseLevels(model, colors, input, options, starting_point,
                                                     sweeps, &coarse, &result.seconds_preparation);

  result.prepared_ahead = ahead.energy != nullptr;
  PreparedFrame frame = result.prepared_ahead
                            ? std::move(ahead)
                            : PrepareLevel(model, colors, input, options,
                                           FrameImageModels(input, options.image), sweeps);
  result.num_surface_gaussians = frame.energy->num_parameters();
  result.k_max = frame.k_max;
  result.num_image_gaussians = frame.num_image_gaussians;
  result.num_pairs = frame.energy->num_pairs();
  result.seconds_preparation += frame.seconds;

  // The frame got worse or better against where it started, before any level moved it. A start
  // handed in (the frame before's k) may lie in a range this frame did not widen to.
  const Eigen::VectorXd initial = WithinRange(starting_point(&frame), frame.k_max);
  Eigen::VectorXd k = coarse_k.size() > 0 ? WithinRange(coarse_k, frame.k_max) : initial;
  TakeTheFrameBefore(input, frame.energy.get());
  // The ends are measured below when a coarser level or the detail stage moved k.
  const bool detail = UsesSurfaceSamples(options);
  result.summary =
      SolveFrameEnergy(frame.energy.get(), options, &k, coarse_k.size() == 0 && !detail, workspace);
  if (coarse_k.size() > 0) {
    if (!detail) {
      EvaluateEnergyAndCost(frame.energy.get(), initial, &result.summary.energy_start,
                            &result.summary.ls_cost_start);
      EvaluateEnergyAndCost(frame.energy.get(), k, &result.summary.energy_end,
                            &result.summary.ls_cost_end);
    }
    result.summary.AddWork(coarse);
  }
  if (detail) {
    const double seconds = frame.seconds;
    SolverSummary summary = SolveDetailStage(model, input, options, &frame, &k);
    result.seconds_preparation += frame.seconds - seconds;
    result.camera_shift = frame.camera_shift;
    EvaluateEnergyAndCost(frame.energy.get(), initial, &summary.energy_start,
                          &summary.ls_cost_start);
    if (options.energy.consensus.passes > 1) {
      EvaluateEnergyAndCost(frame.energy.get(), k, &summary.energy_end, &summary.ls_cost_end);
    }
    summary.AddWork(result.summary);
    result.summary = summary;
  }
  result.k_solved = k;
  result.worse = result.summary.energy_end < result.summary.energy_start;
  // With no surface Gaussian (no camera sees a refined vertex) the input is all there is.
  result.kept_input = (result.worse && options.keep_input_if_worse) || k.size() == 0;

  const double bias = BiasCompensation(options);
  result.refined = frame.fine;
  result.k = Eigen::VectorXd::Constant(frame.fine.num_vertices(), std::nan(""));
  result.confidence = result.k;
  const std::vector<int>& ids = frame.energy->surface().vertex_ids;
  for (size_t s = 0; s < ids.size(); ++s) {
    result.confidence[ids[s]] = frame.energy->confidence()[s];
    const double displacement = result.kept_input ? 0.0 : k[s] + bias;
    result.k[ids[s]] = displacement;
    result.refined.vertices.col(ids[s]) += displacement * frame.normals.col(ids[s]);
  }
  result.normals = ComputeVertexNormals(result.refined);
  if (options.energy.consensus.shared_appearance && UsesSurfaceSamples(options)) {
    const Eigen::VectorXd displacement = result.kept_input
                                             ? Eigen::VectorXd(Eigen::VectorXd::Zero(k.size()))
                                             : Eigen::VectorXd(k.array() + bias);
    result.appearance = frame.energy->SampleAppearance(displacement);
  }
  result.seconds_total = SecondsSince(start);
  return result;
}

}  // namespace

double ConfidentShare(const FrameResult& result) {
  int refined = 0, confident = 0;
  for (double confidence : result.confidence) {
    if (std::isnan(confidence)) continue;
    ++refined;
    confident += confidence >= kConfidentAt;
  }
  return refined > 0 ? static_cast<double>(confident) / refined : std::nan("");
}

namespace {

// How many times the edges of the configured level are halved from the input subdivided once.
int HalvingsPastLevelOne(const RefineOptions& options) {
  return std::max(options.subdivision_levels - 1, 0);
}

}  // namespace

int PatchRingsAt(const RefineOptions& options) {
  return std::min(options.energy.consensus.patch_rings << HalvingsPastLevelOne(options),
                  ConsensusOptions::kMaxPatchRings);
}

int SmoothingRoundsAt(const RefineOptions& options, int rounds) {
  return rounds << (2 * HalvingsPastLevelOne(options));
}

double WidestSearchRange(const RefineOptions& options) {
  double k_max = options.energy.k_max;
  const SweepOptions& sweep = options.sweep;
  if (sweep.samples == 0 || sweep.widen_share <= 0.0) return k_max;
  for (int widening = 0; widening < sweep.max_widenings && k_max < EnergyOptions::kLargestKMax;
       ++widening) {
    k_max = WidenedRange(k_max);
  }
  return k_max;
}

double BiasCompensation(const RefineOptions& options) {
  return options.bias_compensation ? options.sigma_hat : 0.0;
}

Eigen::VectorXd SolvedDisplacement(const Eigen::VectorXd& k, bool kept_input,
                                   const RefineOptions& options) {
  if (kept_input) return k;
  return k.array() - BiasCompensation(options);
}

void KeepInputSurface(const Mesh& fine_input, FrameResult* result) {
  result->refined = fine_input;
  result->normals = ComputeVertexNormals(fine_input);
  result->k = result->k.array().isFinite().select(0.0 * result->k, result->k);
  result->kept_input = true;
  result->appearance.resize(3, 0);
}

Eigen::VectorXd StartingPoint(PreparedFrame* frame, const SweepOptions& sweep,
                              const Eigen::VectorXd* warm_start) {
  FrameEnergy* energy = frame->energy.get();
  if (warm_start != nullptr && warm_start->size() == energy->num_parameters()) return *warm_start;
  if (frame->sweep_start.size() == energy->num_parameters()) return frame->sweep_start;
  return SweepInitialization(energy, sweep);
}

FrameResult RefineFrame(const SequenceModel& model, const ReferenceColors& colors,
                        const FrameInput& input, const RefineOptions& options,
                        const Eigen::VectorXd* warm_start, PreparedFrame ahead,
                        SolverWorkspace* workspace) {
  return RefineFrameStartingAt(
      model, colors, input, options,
      [&](PreparedFrame* frame) {
        return StartingPoint(frame, SweepOptionsAt(options), warm_start);
      },
      /*sweeps=*/warm_start == nullptr || warm_start->size() == 0, std::move(ahead), workspace);
}

FrameResult RefineFrameFrom(const SequenceModel& model, const ReferenceColors& colors,
                            const FrameInput& input, const RefineOptions& options,
                            const Eigen::VectorXd& start, PreparedFrame ahead,
                            SolverWorkspace* workspace) {
  Require(start.size() == model.num_fine_vertices(), "refine",
          "a start of " + std::to_string(start.size()) + " displacements for " +
              std::to_string(model.num_fine_vertices()) + " fine vertices");
  return RefineFrameStartingAt(
      model, colors, input, options,
      [&](PreparedFrame* frame) {
        Eigen::VectorXd k = StartingPoint(frame, SweepOptionsAt(options), nullptr);
        const std::vector<int>& ids = frame->energy->surface().vertex_ids;
        for (size_t s = 0; s < ids.size(); ++s) {
          if (std::isfinite(start[ids[s]])) k[s] = start[ids[s]];
        }
        return k;
      },
      /*sweeps=*/true, std::move(ahead), workspace);
}

}  // namespace finecap
