#include "refine/scene_scale.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "finecap/energy/similarity_needs.h"
#include "finecap/geometry/mesh_edges.h"
#include "finecap/geometry/subdivision.h"
#include "finecap/io/capture.h"
#include "finecap/util/error.h"

namespace finecap {
namespace {

double MeanEdgeLength(const Mesh& mesh) {
  const MeshEdges edges = BuildMeshEdges(mesh.faces);
  if (edges.num_edges() == 0) return 0.0;
  double sum = 0.0;
  for (int e = 0; e < edges.num_edges(); ++e) {
    sum +=
        (mesh.vertices.col(edges.vertices(0, e)) - mesh.vertices.col(edges.vertices(1, e))).norm();
  }
  return sum / edges.num_edges();
}

// Median of depth / focal over every (camera, vertex in front of it and inside its image).
double MedianPixelFootprint(const Mesh& mesh, const std::vector<Camera>& cameras) {
  std::vector<double> footprints;
  for (const Camera& camera : cameras) {
    const Camera pinhole = camera.Undistorted();
    for (int v = 0; v < mesh.num_vertices(); ++v) {
      const double depth = pinhole.Depth(mesh.vertices.col(v));
      if (!(depth > 0.0)) continue;
      const Eigen::Vector2d pixel = pinhole.Project(mesh.vertices.col(v));
      if (pixel.x() < 0 || pixel.y() < 0 || pixel.x() >= camera.width ||
          pixel.y() >= camera.height) {
        continue;
      }
      footprints.push_back(depth / pinhole.focal());
    }
  }
  if (footprints.empty()) return 0.0;
  const auto middle = footprints.begin() + footprints.size() / 2;
  std::nth_element(footprints.begin(), middle, footprints.end());
  return *middle;
}

// Replaces `*value` by max(factor * scene length, at_least) when `from_scene`, and reports it.
ChosenLength Choose(const std::string& field, double factor, double scene_length, double* value,
                    bool from_scene, double at_least = 0.0) {
  if (from_scene) *value = std::max(factor * scene_length, at_least);
  return {field, *value, from_scene};
}

}  // namespace

std::string LengthText(double metres) {
  std::ostringstream text;
  text << std::setprecision(3);
  if (std::abs(metres) >= 1.0) {
    text << metres << " m";
  } else {
    text << 1000.0 * metres << " mm";
  }
  return text.str();
}

SceneScale MeasureSceneScale(const Mesh& fine, const std::vector<Camera>& cameras) {
  SceneScale scale;
  scale.diagonal = BoundingBoxDiagonal(fine);
  scale.mean_edge_length = MeanEdgeLength(fine);
  scale.pixel_footprint = MedianPixelFootprint(fine, cameras);
  scale.length =
      std::max(scale.mean_edge_length, kFootprintsPerSceneLength * scale.pixel_footprint);
  return scale;
}

SceneScaleDefaults ResolveSceneScaleDefaults(const Mesh& reference_coarse,
                                             const std::vector<Camera>& cameras,
                                             const std::string& where, RefineOptions* options) {
  const SubdivisionStencil stencil =
      BuildSubdivision(options->subdivision, reference_coarse, options->subdivision_levels, where);
  SceneScaleDefaults defaults;
  defaults.scale =
      MeasureSceneScale(ApplySubdivision(stencil, reference_coarse.vertices, where), cameras);
  const double s = defaults.scale.length;
  Require(s > 0.0, where,
          "the mesh has no extent (every edge has length 0), so no length can follow from it");
  const SceneLengthFactors factors;
  const SceneLengths& marks = options->scene_lengths;
  defaults.lengths = {
      Choose("RefineOptions::sigma_hat",
             NeedsOf(options->energy).compares_patches ? factors.sigma_hat
                                                       : factors.single_gaussian_sigma_hat,
             s, &options->sigma_hat, marks.sigma_hat),
      Choose("EnergyOptions::k_max", factors.k_max, s, &options->energy.k_max, marks.k_max,
             factors.k_max_of_diagonal * defaults.scale.diagonal),
      Choose("VisibilityOptions::depth_tolerance", factors.depth_tolerance, s,
             &options->visibility.depth_tolerance, marks.depth_tolerance),
      Choose("SolverOptions::initial_step", factors.initial_step, s, &options->solver.initial_step,
             marks.initial_step),
      Choose("SolverOptions::max_step", factors.max_step, s, &options->solver.max_step,
             marks.max_step),
  };
  return defaults;
}

SceneScaleDefaults ResolveSceneScaleDefaults(const Capture& capture, int reference_frame,
                                             RefineOptions* options) {
  Require(reference_frame >= 0 && reference_frame < capture.num_frames(),
          "SequenceOptions::reference_frame",
          "frame " + std::to_string(reference_frame) + " does not exist in " + capture.directory() +
              " (" + std::to_string(capture.num_frames()) + " frames)");
  return ResolveSceneScaleDefaults(capture.ReadCoarseMesh(reference_frame), capture.cameras(),
                                   capture.mesh_path(reference_frame), options);
}

std::string DescribeSceneScaleDefaults(const SceneScaleDefaults& defaults) {
  const SceneScale& scale = defaults.scale;
  std::ostringstream text;
  text << "scene length " << LengthText(scale.length) << " = max(mean edge after subdivision "
       << LengthText(scale.mean_edge_length) << ", " << kFootprintsPerSceneLength
       << " x pixel footprint " << LengthText(scale.pixel_footprint) << "); ";
  for (size_t i = 0; i < defaults.lengths.size(); ++i) {
    const ChosenLength& length = defaults.lengths[i];
    text << (i ? ", " : "") << length.field << " " << LengthText(length.value)
         << (length.from_scene ? " (auto)" : " (set)");
  }
  return text.str();
}

void SceneScaleLimits::Check() const {
  Require(min_sigmas > 0.0, "SceneScaleLimits::min_sigmas", "must be positive");
  Require(max_sigmas > min_sigmas, "SceneScaleLimits::max_sigmas", "must exceed min_sigmas");
}

double BoundingBoxDiagonal(const Mesh& mesh) {
  if (mesh.num_vertices() == 0) return 0.0;
  return (mesh.vertices.rowwise().maxCoeff() - mesh.vertices.rowwise().minCoeff()).norm();
}

void RequirePlausibleSceneScale(const Mesh& mesh, double sigma_hat, const std::string& where,
                                const SceneScaleLimits& limits) {
  limits.Check();
  Require(sigma_hat > 0.0, "sigma_hat", "must be positive");
  const double diagonal = BoundingBoxDiagonal(mesh);
  const double sigmas = diagonal / sigma_hat;
  if (sigmas >= limits.min_sigmas && sigmas <= limits.max_sigmas) return;
  std::ostringstream problem;
  problem.precision(4);
  problem << "the coarse mesh measures " << diagonal << " across (bounding-box diagonal), "
          << sigmas << " times RefineOptions::sigma_hat = " << sigma_hat
          << "; finecap's lengths are metres";
  if (sigmas > limits.max_sigmas) {
    problem << ", and a mesh this large looks like one in millimetres or centimetres: convert the "
               "capture (meshes and camera translations) to metres, or raise "
               "RefineOptions::sigma_hat for "
               "a subject larger than "
            << limits.max_sigmas * sigma_hat << " m";
  } else {
    problem
        << ", and a mesh this small is too small for the surface Gaussians (or in a larger "
           "unit than metres): convert the capture to metres, or lower RefineOptions::sigma_hat "
           "(and EnergyOptions::k_max) for a subject smaller than "
        << limits.min_sigmas * sigma_hat << " m";
  }
  throw Error(where, problem.str());
}

}  // namespace finecap
