// finecap info: the capture as finecap reads it and the problem a refinement would solve, without
// refining or writing anything. Every figure comes from the library functions a run uses.
#include <algorithm>
#include <cmath>
#include <iostream>

#include "commands/command_util.h"
#include "finecap/commands/commands.h"
#include "finecap/refine/problem_size.h"
#include "finecap/refine/shard.h"
#include "refine/scene_scale.h"

namespace finecap {
namespace {

// `training` are the cameras refine uses (size.visible_per_camera follows them); the held-out ones
// are listed after them.
void PrintCameras(const Capture& capture, const std::vector<Camera>& training,
                  const std::vector<CalibratedImage>& held_out, const ProblemSize& size) {
  std::cout << "cameras: " << capture.num_cameras() << ", read from " << capture.rig_source()
            << "\n";
  for (size_t c = 0; c < training.size(); ++c) {
    const Camera& camera = training[c];
    std::cout << "  " << camera.name << ": " << camera.width << "x" << camera.height << ", focal "
              << camera.focal() << " px"
              << (camera.HasDistortion() ? ", lens distortion (undistorted on load)" : "")
              << ", sees " << size.visible_per_camera[c] << " fine vertices\n";
  }
  for (const CalibratedImage& view : held_out) {
    std::cout << "  " << view.camera.name << ": held out (validation.cameras), scored by refine "
              << "and eval only\n";
  }
}

void PrintFrames(const Capture& capture, const FrameRange& frames, int reference_frame) {
  std::cout << "frames: " << capture.num_frames() << " (" << capture.frame_name(0) << " .. "
            << capture.frame_name(capture.num_frames() - 1) << "), " << frames.size()
            << " to refine (" << frames.begin << ":" << frames.end << "), reference frame "
            << capture.frame_name(reference_frame) << "\n";
}

void PrintWarnings(const Config& config, const std::vector<Camera>& training,
                   const ProblemSize& size) {
  for (size_t c = 0; c < training.size(); ++c) {
    if (size.visible_per_camera[c] > 0) continue;
    std::cout << "warning: camera " << training[c].name
              << " sees no vertex of the mesh (behind it, out of its image, or every vertex "
                 "beyond the view-angle cap): check its calibration and units\n";
  }
  if (size.num_unseen_refined_vertices > 0) {
    const VisibilityOptions& visibility = config.refine.visibility;
    const bool fallback = FallbackCamerasWanted(config.refine) > 0;
    std::cout << "warning: " << size.num_unseen_refined_vertices << " of "
              << size.num_refined_vertices << " vertices to refine are seen by no camera within "
              << (fallback ? "visibility.fallback_view_angle_deg "
                           : "visibility.max_view_angle_deg ")
              << (fallback ? visibility.fallback_view_angle_deg : visibility.max_view_angle_deg)
              << " degrees; they keep the input surface\n";
  }
  if (size.num_refined_vertices == 0) return;
  const double well_seen =
      static_cast<double>(size.num_well_seen_refined_vertices) / size.num_refined_vertices;
  if (well_seen < internal::kUsefulConfidentShare) {
    std::cout << "warning: too few views for this capture to be refined usefully: "
              << internal::TooFewViewsReason(well_seen) << "; refine would keep the rest near "
              << "the input\n";
  }
}

}  // namespace

int RunInfo(const Config& configured) {
  Capture capture = internal::OpenConfiguredCapture(configured);
  const FrameRange frames =
      ShardOf(internal::ConfiguredFrames(configured, capture), configured.runtime.shard);
  SceneScaleDefaults defaults;
  const Config config = internal::WithSceneLengths(configured, capture, "info", &defaults);

  const SequenceModel model(capture.ReadCoarseMesh(0), capture.vertex_mask(), config.refine,
                            capture.mesh_path(0));
  FrameInput reference = ReadFrameInput(&capture, config.reference_frame);
  TakeHeldOutViews(config.validation.cameras, &reference);  // As refine colours the surface.
  const ReferenceColors colors = ComputeSequenceColors(model, reference, config.refine);
  const int first = frames.size() > 0 ? frames.begin : config.reference_frame;
  FrameInput input = ReadFrameInput(&capture, first);
  const std::vector<CalibratedImage> held_out = TakeHeldOutViews(config.validation.cameras, &input);
  ProblemSize size = EstimateProblemSize(model, colors, input, config.refine,
                                         std::max(frames.size(), 1), UndistortedPixels(capture));
  AddHeldOutScoring(held_out, static_cast<int>(input.cameras.size()),
                    config.validation.score.neighbours, &size);

  std::cout << "capture: " << capture.directory() << "\n";
  PrintCameras(capture, input.cameras, held_out, size);
  PrintFrames(capture, frames, config.reference_frame);
  const Mesh coarse = capture.ReadCoarseMesh(0);
  std::cout << "mesh: " << coarse.num_vertices() << " vertices, " << coarse.num_faces()
            << " faces; " << size.num_fine_vertices << " vertices after "
            << config.refine.subdivision_levels << " subdivision level(s) ("
            << config.refine.subdivision << ")\n";
  const SceneScale& scale = defaults.scale;
  std::cout << "scene: extent " << LengthText(scale.diagonal)
            << " (bounding-box diagonal), mean edge after subdivision "
            << LengthText(scale.mean_edge_length) << ", pixel footprint "
            << LengthText(scale.pixel_footprint) << ", scene length " << LengthText(scale.length)
            << "\n";
  std::cout << "lengths:";
  for (size_t i = 0; i < defaults.lengths.size(); ++i) {
    const ChosenLength& length = defaults.lengths[i];
    std::cout << (i ? ", " : " ") << ConfigKeyOfField(length.field) << " "
              << LengthText(length.value) << (length.from_scene ? " (auto)" : " (set)");
  }
  std::cout << "\n";
  std::cout << "vertices refined: " << size.num_surface_gaussians << " of "
            << size.num_refined_vertices << " to refine ("
            << (capture.has_vertex_mask() ? "mask.txt" : "no mask: all") << "), "
            << size.num_unseen_refined_vertices << " seen by no camera, "
            << size.num_well_seen_refined_vertices
            << " seen well enough by enough cameras to be refined with confidence where textured\n";
  std::cout << "problem per frame: " << size.num_image_gaussians << " image Gaussians, about "
            << internal::RoundedCount(size.num_pairs) << " pairs of Gaussians, "
            << size.num_observations << " observations\n";
  std::cout << "forecast per frame: peak memory " << std::lround(size.peak_memory_mb) << " MB"
            << internal::WidestRangeForecast(size) << ", about "
            << internal::RoundedSeconds(size.seconds_per_frame) << " ("
            << internal::RoundedSeconds(size.seconds_per_frame * frames.size()) << " for "
            << frames.size() << " frames)\n";
  PrintWarnings(config, input.cameras, size);
  return 0;
}

}  // namespace finecap
