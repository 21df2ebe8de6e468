// The surface model of the energy: one isotropic 3D Gaussian per refined vertex, sliding along the
// vertex normal, mu_s(k_s) = base_s + k_s * normal_s, with a colour eta_s taken once per sequence
// from a reference frame (the paper's section 4.1).
#ifndef FINECAP_SURFACE_GAUSSIANS_H_
#define FINECAP_SURFACE_GAUSSIANS_H_

#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "finecap/geometry/camera.h"
#include "finecap/geometry/color.h"
#include "finecap/model/gaussian_overlap.h"
#include "finecap/model/image_gaussians.h"
#include "finecap/util/enum_names.h"

namespace finecap {

// The surface Gaussians of one frame.
struct SurfaceGaussians {
  std::vector<int> vertex_ids;          // The mesh vertex each Gaussian sits on.
  Eigen::Matrix3Xd base;                // Positions at k = 0 (the input vertices), metres.
  Eigen::Matrix3Xd normals;             // Unit normals of the input mesh.
  std::vector<Eigen::Vector3f> colors;  // eta_s, embedded in `color_space` (see color.h).
  ColorSpace color_space = ColorSpace::kHsv;
  double sigma_hat = 0.007;  // Standard deviation, metres (paper: 7 mm).
  // How well this frame's cameras see each Gaussian, in [0, 1] (ViewConfidence, visibility.h);
  // empty: fully, everywhere.
  std::vector<float> view_confidence;
  // Where the input as given lies from each Gaussian along its normal, metres: an approximating
  // subdivision (Loop) moves the input's surface, and a pull towards the input means towards
  // this. Empty: at k = 0.
  std::vector<double> input_offset;

  int size() const { return static_cast<int>(vertex_ids.size()); }
};

// How the reference frame colours the surface Gaussians: the mean of the pixels under each
// projected Gaussian (the paper), or what the image model shows there.
enum class ReferenceColorSource { kPixels, kImageModel };
const std::vector<EnumName<ReferenceColorSource>>& EnumNames(ReferenceColorSource);

// Colours of the vertices of a mesh, taken from one frame's images, with a flag per vertex that
// says whether any camera saw it. Saved once per sequence so that any frame can run on its own.
struct ReferenceColors {
  ColorSpace color_space = ColorSpace::kHsv;
  double sigma_hat = 0.007;  // The footprint they were averaged over, metres.
  ReferenceColorSource method = ReferenceColorSource::kPixels;  // How they were taken.
  // What they were computed from, one line (ReferenceColorRecipe, sequence.h); saved in the file
  // so that a run reusing it can check it. Empty in files saved before recipes were.
  std::string recipe;
  std::vector<Eigen::Vector3f> colors;  // One per mesh vertex.
  std::vector<unsigned char> valid;     // 1 where a camera saw the vertex.
};

// The paper's colouring: for each vertex, the camera that sees it best (visible, and whose
// viewing direction aligns best with the normal), where the mean of the pixel colours under the
// projected Gaussian (weights of the Gaussian, out to 2 sigma) becomes its colour.
// `visible[c][v]` says whether camera c sees vertex v; `images[c]` are the undistorted 8-bit
// BGR images of that frame.
ReferenceColors ComputeReferenceColors(const Eigen::Matrix3Xd& vertices,
                                       const Eigen::Matrix3Xd& normals,
                                       const std::vector<Camera>& cameras,
                                       const std::vector<cv::Mat>& images,
                                       const std::vector<std::vector<unsigned char>>& visible,
                                       ColorSpace color_space, double sigma_hat);

// The same choice of camera, but the colour is what the colour similarity's image model shows
// there at k = 0: the overlap-weighted mean of the image Gaussians' colours
// (surface_color_similarity.h), so that in the reference frame the colour residual of the best
// camera is exactly zero and no blur difference between pixels and image model remains.
ReferenceColors ComputeModelReferenceColors(const Eigen::Matrix3Xd& vertices,
                                            const Eigen::Matrix3Xd& normals,
                                            const std::vector<Camera>& cameras,
                                            const std::vector<ImageGaussians>& images,
                                            const std::vector<std::vector<unsigned char>>& visible,
                                            double sigma_hat, OverlapForm form,
                                            double reach_sigmas);

// A text file, one vertex a line; the header states the colour space and sigma_hat. Written
// atomically. Reading throws Error naming the file when it is malformed or was made for another
// number of vertices (`expected_vertices`, or any when negative).
void WriteReferenceColors(const std::string& path, const ReferenceColors& colors);
ReferenceColors ReadReferenceColors(const std::string& path, int expected_vertices = -1);

// The surface Gaussians of a frame: one per vertex in `vertex_ids` whose reference colour is
// valid and whose normal is defined.
SurfaceGaussians MakeSurfaceGaussians(const Eigen::Matrix3Xd& vertices,
                                      const Eigen::Matrix3Xd& normals,
                                      const std::vector<int>& vertex_ids,
                                      const ReferenceColors& colors);

}  // namespace finecap

#endif  // FINECAP_SURFACE_GAUSSIANS_H_
