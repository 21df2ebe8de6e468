// A small CPU z-buffer rasteriser: depth, triangle-id, colour and normal images of a mesh seen by
// a pinhole camera.
//
// It runs on the CPU on purpose (as OpenMVS does): no GL context is needed on a headless machine
// or in CI, and every pixel convention is under exact control. Conventions:
//   * The camera is used as a pinhole: its lens distortion is ignored (render with the true
//     camera, then distort the image if a distorted picture is wanted).
//   * A pixel's value is the surface seen through its centre; pixel centres sit at integer
//     coordinates, the centre of the top-left pixel at (0, 0), as in camera.h. With supersampling
//     factor s a pixel is the mean of s x s samples on a regular grid inside it.
//   * Depth is the camera z of the surface point in metres (not the distance to the centre).
//   * Triangles are clipped against the near plane z = near_plane: a triangle crossing it is cut
//     there and its front part drawn; nothing behind the camera is ever projected.
//   * Attributes (barycentrics, colours, UVs, normals) are interpolated perspective-correctly.
//   * Ties in depth go to the triangle with the lower index, so every render is deterministic
//     whatever the number of threads (rows are split into bands rendered in parallel with OpenMP).
#ifndef FINECAP_GEOMETRY_RENDER_H_
#define FINECAP_GEOMETRY_RENDER_H_

#include <cstdint>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "finecap/geometry/camera.h"
#include "finecap/geometry/mesh.h"
#include "finecap/util/option_fields.h"

namespace finecap {

// How images are rendered. The fields are documented where Fields() declares them
// (docs/configuration.md: synth.render); the comments below add what the documentation does not
// say.
struct RenderOptions {
  // A colour pixel is the mean of s*s samples; 1 samples the pixel centre only. Ignored by
  // RenderDepth, which always samples pixel centres.
  int supersampling = 2;

  // The front side has counter-clockwise corners (mesh.h). Off: an open surface such as a skirt
  // shows its inside through its hem.
  bool cull_back_faces = false;

  double near_plane = 0.01;

  // n is the interpolated vertex normal turned towards the camera (so the inside of an open
  // surface is lit like its outside), l the unit direction towards the light. Off: the colour is
  // the albedo.
  bool shade = false;
  double ambient = 0.35;
  double diffuse = 0.65;
  // A directional light; (0.3, 1, -0.5) is from above, slightly in front.
  Eigen::Vector3d light_direction = Eigen::Vector3d(0.3, 1.0, -0.5);

  Eigen::Vector3d background = Eigen::Vector3d::Zero();

  double noise_sigma = 0.0;
  std::uint64_t noise_seed = 0;  // The same seed gives the same noise.

  static const OptionFields<RenderOptions>& Fields();  // option_fields.h
  // Throws Error naming the offending field when a value is out of range.
  void Check() const;
};

// What a colour render paints on the mesh: exactly one of
//   * `vertex_colors`: RGB in [0, 1], one column per vertex; or
//   * `corner_uvs` + `texture`: a texture coordinate per triangle corner (column 3*f + c holds
//     corner c of face f, so seams need no duplicated vertices) into an 8-bit BGR image (OpenCV's
//     channel order), sampled bilinearly with wrap-around addressing. (u, v) = (0, 0) is the
//     top-left corner of the top-left texel and (1, 1) the bottom-right corner of the
//     bottom-right texel: v grows downwards like image rows.
struct SurfaceAppearance {
  Eigen::Matrix3Xd vertex_colors;
  Eigen::Matrix2Xd corner_uvs;
  cv::Mat texture;  // CV_8UC3.
};

// Nearest surface per pixel centre.
struct DepthMap {
  cv::Mat depth;         // CV_32F, camera z in metres; +infinity where no triangle is seen.
  cv::Mat triangle_ids;  // CV_32S, index of the face seen; -1 where none.
};

// Depth and triangle ids at pixel centres: the cheap entry point for visibility tests. Uses only
// `cull_back_faces` and `near_plane` of `options`. Throws Error if the camera or mesh is invalid.
DepthMap RenderDepth(const Camera& camera, const Mesh& mesh,
                     const RenderOptions& options = RenderOptions());

// An 8-bit BGR image (CV_8UC3, ready for cv::imwrite) of the mesh painted with `appearance`.
// Throws Error if the camera, mesh, appearance or options are invalid.
cv::Mat RenderColor(const Camera& camera, const Mesh& mesh, const SurfaceAppearance& appearance,
                    const RenderOptions& options = RenderOptions());

// Colour-coded normals as in the paper's figures: the interpolated unit vertex normal (area
// weighted, see mesh.h) in camera coordinates n maps to RGB = (n + 1) / 2. Shading and noise
// options are ignored; supersampling, culling and background are used. BGR CV_8UC3 like
// RenderColor.
cv::Mat RenderNormals(const Camera& camera, const Mesh& mesh,
                      const RenderOptions& options = RenderOptions());

// Adds independent Gaussian noise of standard deviation `sigma` (grey levels) to every value of
// an 8-bit image, rounding and saturating; the same seed gives the same noise. Throws Error for a
// negative sigma or an image that is not 8-bit.
void AddSensorNoise(double sigma, std::uint64_t seed, cv::Mat* image);

}  // namespace finecap

#endif  // FINECAP_GEOMETRY_RENDER_H_
