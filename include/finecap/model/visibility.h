// Which surface points a camera sees: in front of it, inside its image, facing it, and not
// hidden behind another part of the surface according to a depth map rendered from the input
// mesh (the paper evaluates its energy only for visible surface Gaussians).
#ifndef FINECAP_VISIBILITY_H_
#define FINECAP_VISIBILITY_H_

#include <limits>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "finecap/geometry/camera.h"
#include "finecap/util/option_fields.h"

namespace finecap {

// Which cameras see a point. The fields are documented where Fields() declares them
// (docs/configuration.md: visibility); the comments below add what the documentation does not say.
struct VisibilityOptions {
  // 0.01: the input mesh is coarse, folds move the true surface by up to ~2 cm. A refinement
  // makes it follow from the scene unless set (RefineOptions::scene_lengths).
  double depth_tolerance = 0.01;
  // Beyond it the point is back-facing or seen so obliquely that folds hide parts of it and a
  // small k moves its projection far. 60 for the consensus similarity, which needs two cameras
  // that see a patch: with a ring of 8 cameras 45 degrees apart, 35 degrees left 87 % of
  // synth_skirt's Gaussians with fewer than two. surface_color, which needs one, peaks closer to
  // the truth with 35 (skirt: 0.77 at 75, 0.95 at 35; configs/surface_color.yaml).
  double max_view_angle_deg = 60.0;
  // ComputeFrameVisibility's `wanted` cameras. On a sparse rig most of the surface faces one
  // camera and lies between two others (four cameras 90 degrees apart: 79 % of synth_skirt's
  // vertices have one camera within 60 degrees). Evidence from steep views is weaker, and the
  // view confidence (ViewConfidence) says how much weaker. At least max_view_angle_deg.
  double fallback_view_angle_deg = 85.0;
  // Two cameras far apart see a point from opposite sides of its normal, each steeply: a fold's
  // flank that faces one of them turns away from the other, and a patch's two images differ by
  // more than its shape can explain. Their agreement then has rival minima a texture's period
  // apart. Two views of a synthetic fold 45 degrees apart recover it to 3.7 mm, 90 degrees apart to
  // 7.7 mm (true 8.4 mm); a ring of three cameras (every pair 120 degrees apart) made a printed
  // skirt worse than its input, where four (90 degrees) recover 17 % of the skirt's detail
  // (docs/measurements.md, 2026-12-08). So a vertex's view confidence also asks that two of its
  // cameras be within max_pair_angle_deg of each other, falling to nothing at
  // fallback_pair_angle_deg: a ring of four keeps its pairs (90 degrees apart, some more where one
  // camera stands higher than the other), a ring of three (120 degrees) has none.
  double max_pair_angle_deg = 105.0;
  double fallback_pair_angle_deg = 120.0;
  // The detail stage (ConsensusOptions::sample_spacing above 0) reads a patch's samples at the
  // images' own resolution, so a steep view is modelled as the camera sees it, foreshortened,
  // where a surface Gaussian several pixel footprints wide smears it; and it chooses its cameras
  // at the surface the surface Gaussians found, whose normals follow the folds the input lacks.
  // More cameras per patch then pay: synth_skirt_exact (each vertex seen by two or three of
  // eight cameras within 60 degrees) recovers 38.7 % of the detail with the first stage's
  // cameras, and 34.7, 42.4, 44.3, 43.8, 42.9 and 40.8 % at 60, 65, 70, 75, 80 and 85 degrees of
  // the surface found; 70-80 hold the other captures' best too (docs/measurements.md,
  // 2026-12-05 (night)).
  double sample_view_angle_deg = 75.0;
  double border_margin = 2.0;

  static const OptionFields<VisibilityOptions>& Fields();  // option_fields.h
  void Check() const;
};

// visible[p] = 1 when `camera` sees point p with unit normal `normals.col(p)`. `depth_map` is a
// CV_32F image of the camera's size holding the depth (camera z) of the nearest surface at each
// pixel, +infinity where there is none.
std::vector<unsigned char> ComputeVisibility(const Camera& camera, const cv::Mat& depth_map,
                                             const Eigen::Matrix3Xd& points,
                                             const Eigen::Matrix3Xd& normals,
                                             const VisibilityOptions& options);

// Narrows `visible` (per camera, which points it sees within options.fallback_view_angle_deg,
// as ComputeVisibility with max_view_angle_deg set to it gives) to the cameras within
// options.max_view_angle_deg, except that a point that fewer than `wanted` of those see keeps the
// most frontal others until it has `wanted` (or all it has).
void KeepFrontalViews(const std::vector<Camera>& cameras, const Eigen::Matrix3Xd& points,
                      const Eigen::Matrix3Xd& normals, int wanted, const VisibilityOptions& options,
                      std::vector<std::vector<unsigned char>>* visible);

// Narrows `visible` to the `count` cameras that see each point most frontally (all it has when
// fewer).
void KeepMostFrontalViews(const std::vector<Camera>& cameras, const Eigen::Matrix3Xd& points,
                          const Eigen::Matrix3Xd& normals, int count,
                          std::vector<std::vector<unsigned char>>* visible);

// How well `wanted` cameras see each point, in [0, 1], from the cameras `visible` says see it: 1
// when the wanted-th most frontal of them is within options.max_view_angle_deg, falling linearly
// in the cosine of its angle to 0 at options.fallback_view_angle_deg; 0 when fewer than `wanted`
// see it. With `wanted` >= 2 it is multiplied by how close the narrowest pair of those cameras is:
// 1 when two of them are within options.max_pair_angle_deg of each other (the angle between their
// directions to the point), falling linearly in the cosine to 0 at
// options.fallback_pair_angle_deg. `wanted` >= 1.
std::vector<float> ViewConfidence(const std::vector<Camera>& cameras,
                                  const Eigen::Matrix3Xd& points, const Eigen::Matrix3Xd& normals,
                                  int wanted, const VisibilityOptions& options,
                                  const std::vector<std::vector<unsigned char>>& visible);

// The camera that sees `point` most frontally: among the cameras c for which `sees(c)` holds,
// the one whose direction from `point` aligns best with `normal` (largest dot product; `normal`
// need not be unit, only its direction matters for the choice), the first of equals; -1 when
// none sees it. The one rule by which a surface point takes its colour from one camera (the
// reference colours, the texture of the flow evaluation).
template <typename Sees>
int MostFrontalCamera(const Eigen::Vector3d& point, const Eigen::Vector3d& normal,
                      const std::vector<Camera>& cameras, const Sees& sees) {
  int best = -1;
  double best_alignment = -std::numeric_limits<double>::infinity();
  for (int c = 0; c < static_cast<int>(cameras.size()); ++c) {
    if (!sees(c)) continue;
    const double alignment = cameras[c].ViewCosine(point, normal);
    if (alignment > best_alignment) {
      best_alignment = alignment;
      best = c;
    }
  }
  return best;
}

}  // namespace finecap

#endif  // FINECAP_VISIBILITY_H_
