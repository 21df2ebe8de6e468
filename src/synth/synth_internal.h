// Parts of the synthetic capture generator shared between its source files (not installed).
#ifndef FINECAP_SRC_SYNTH_INTERNAL_H_
#define FINECAP_SRC_SYNTH_INTERNAL_H_

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "finecap/synth/synth.h"

namespace finecap {
namespace synth_internal {

// Where points sit in the cloth, fixed over time: angle around the vertical axis (radians,
// theta = atan2(z, x) about the subject's axis) and distance down the surface from its top
// (metres).
struct MaterialCoordinates {
  Eigen::VectorXd theta;
  Eigen::VectorXd down;
};

// The unfolded (smooth) surface of one frame.
struct SmoothFrame {
  Eigen::Matrix3Xd coarse_vertices;  // The coarse vertices, on the smooth surface.
  Eigen::Matrix3Xd coarse_normals;   // Unit smooth-surface normals there.
  Eigen::Matrix3Xd fine_vertices;    // The finer vertices of the true surface before folding.
  Eigen::Matrix3Xd fine_normals;     // Unit normals along which the folds displace them.
};

// A subject: its fixed topology, material coordinates and texture layout, and its smooth
// surface at each frame.
class Subject {
 public:
  virtual ~Subject() = default;
  virtual SmoothFrame Smooth(int frame) const = 0;

  Eigen::Matrix3Xi coarse_faces;
  Eigen::Matrix3Xi fine_faces;
  MaterialCoordinates coarse_material;
  MaterialCoordinates fine_material;
  Eigen::Matrix2Xd fine_corner_uvs;  // Per corner of fine_faces, see SurfaceAppearance.
  Eigen::VectorXd coarse_v;          // Texture v of each coarse vertex (0 top, 1 bottom).
  double mean_radius = 0.0;          // Mean distance from the vertical axis, metres.
  double circumference = 0.0;        // Texture u = 0..1 covers this many metres.
  double surface_height = 0.0;       // Texture v = 0..1 covers this many metres.
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  // What the cameras look at.
};

std::unique_ptr<Subject> MakeSkirt(const SkirtOptions& options, int refinement);

// Reads `path` (a mesh file or a folder of per-frame meshes) for `num_frames` frames.
std::unique_ptr<Subject> MakeMeshSubject(const std::string& path, int num_frames, int refinement);

// Material coordinates (theta around the y axis through `axis_point`, distance below `top`).
MaterialCoordinates CylindricalCoordinates(const Eigen::Matrix3Xd& points,
                                           const Eigen::Vector3d& axis_point, double top);

// Sum of the fold components at material points, at `frame` (see FoldComponent).
Eigen::VectorXd FoldDisplacement(const std::vector<FoldComponent>& folds, int ramp_frames,
                                 double mean_radius, const MaterialCoordinates& at, int frame);

// A cloth print: `options.width` x `options.height` BGR texels whose u axis wraps around
// seamlessly. The texture spans `circumference` x `surface_height` metres on the subject, so
// that motifs get a physical size.
cv::Mat MakeClothTexture(const TextureOptions& options, double circumference, double surface_height,
                         std::uint64_t seed);

}  // namespace synth_internal
}  // namespace finecap

#endif  // FINECAP_SRC_SYNTH_INTERNAL_H_
