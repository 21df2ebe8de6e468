// The paper's optical-flow evaluation (section 7, Figure 6), which needs no ground truth: each
// model, textured from the reference frame's images, is rendered into a camera at a later frame,
// and the optical flow between that render and the camera's image says how far the surface seen
// in the render is from where the image shows it. The mean flow length over the subject is taken
// for the subdivided input mesh and for the refined mesh; a better surface gives less flow.
//
// Texture. Each triangle is textured from the reference frame's image of the camera that sees all
// three of its corners most frontally, by projecting the corners into it (projective texturing).
// This is the paper's choice of camera (surface_gaussians.h) at the images' full resolution:
// vertex colours would low-pass the texture to the vertex spacing (~4 px on the synthetic
// captures), and the saved reference colours live in the energy's colour space (chromaticity by
// default drops brightness), which cannot be turned back into an image to compare with.
//
// Each mesh is textured from its own surface in the reference frame: the input mesh from the
// reference frame's input mesh, the refined mesh from the reference frame's refined mesh (camera
// choice and visibility from that surface too). A texture projected onto a wrong surface slides
// over the surface in the other frames, so a single texture taken from the input mesh would
// charge the refined mesh for the input's error in the reference frame wherever that frame has
// detail the input lacks. Where the refined reference frame is not at hand, the input's texture
// paints both meshes (the caller says so), which is fair only when the input is right there.
//
// Conventions: pixels and cameras as in camera.h and render.h (the cameras are those of the
// undistorted images); flow lengths in pixels.
#ifndef FINECAP_EVAL_FLOW_EVALUATION_H_
#define FINECAP_EVAL_FLOW_EVALUATION_H_

#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "finecap/eval/optical_flow.h"
#include "finecap/geometry/camera.h"
#include "finecap/geometry/mesh.h"

namespace finecap {

// A texture for every face of one topology, cut from a frame's images.
struct ProjectiveTexture {
  cv::Mat atlas;                        // CV_8UC3: the images side by side, top-aligned.
  Eigen::Matrix2Xd corner_uvs;          // 3 per face, as SurfaceAppearance::corner_uvs.
  std::vector<unsigned char> textured;  // Per face: 1 when a camera saw all three corners.
};

// Textures the faces of `mesh` (a surface of the reference frame: its subdivided input mesh or
// its refined mesh, with unit vertex `normals`) from `images` (8-bit BGR, one per camera,
// undistorted). `visible[c][v]` says whether camera c sees vertex v (ComputeFrameVisibility). Among
// the cameras that see all three corners of a face, the one whose direction from the face's centre
// best agrees with the corners' mean normal is used. A face no camera sees keeps UVs of the atlas'
// first texel and textured = 0. Throws Error when the counts of cameras, images and visibility
// lists or their sizes disagree.
ProjectiveTexture MakeProjectiveTexture(const Mesh& mesh, const Eigen::Matrix3Xd& normals,
                                        const std::vector<Camera>& cameras,
                                        const std::vector<cv::Mat>& images,
                                        const std::vector<std::vector<unsigned char>>& visible);

// Gives every face that `texture` leaves untextured and `fallback` textures the fallback's UVs
// and marks it textured: the refined reference mesh may hide a face from every camera (deep in a
// fold) that the input shows, and such a face is better painted as the input's texture paints it
// than with one texel. Both textures must come from the same images (the same atlas) and be made
// for one topology; throws Error otherwise.
void FillUntexturedFaces(const ProjectiveTexture& fallback, ProjectiveTexture* texture);

// Per face of `mesh`: 1 when it is textured and at least one corner is in `vertex_ids` (the
// refined vertices), so that the flow is measured where refinement can change something.
std::vector<unsigned char> FacesToMeasure(const Mesh& mesh, const ProjectiveTexture& texture,
                                          const std::vector<int>& vertex_ids);

// `mesh` with `texture`, rendered into `camera` (one sample per pixel) over `image`: pixels that
// see no surface keep the image's, so that outside the subject the flow is zero by construction.
cv::Mat RenderTexturedOverImage(const Camera& camera, const Mesh& mesh,
                                const ProjectiveTexture& texture, const cv::Mat& image);

// 100 (coarse - refined) / coarse, the paper's improvement in percent; NaN unless coarse is a
// positive finite number.
double FlowImprovementPercent(double coarse_px, double refined_px);

// The flow figures of one camera and frame (or of many, added up).
struct FlowComparison {
  FlowMagnitudeSum coarse;   // Input mesh render -> image.
  FlowMagnitudeSum refined;  // Refined mesh render -> image.

  void Add(const FlowComparison& other) {
    coarse.Add(other.coarse);
    refined.Add(other.refined);
  }
  // FlowImprovementPercent of the two means.
  double improvement_percent() const {
    return FlowImprovementPercent(coarse.mean_px(), refined.mean_px());
  }
};

// The images behind one FlowComparison, for pictures.
struct FlowFields {
  cv::Mat mask;     // CV_8U, non-zero at the pixels measured.
  cv::Mat coarse;   // CV_32FC2 flow from the input mesh's render to the image.
  cv::Mat refined;  // CV_32FC2 flow from the refined mesh's render to the image.
};

// Renders `coarse` with `coarse_texture` and `refined` with `refined_texture` (one topology, both
// textures made for it) into `camera`, computes the flow from each render to `image` (the
// camera's undistorted image of the same frame) and sums its length over the same pixels for
// both: those where either mesh shows a face that `faces_to_measure` marks. When `fields` is given
// it receives the mask and both flows. Throws Error(where, ...) when the image is not of the
// camera's size or the counts of faces disagree.
FlowComparison CompareFlow(const Camera& camera, const cv::Mat& image, const Mesh& coarse,
                           const ProjectiveTexture& coarse_texture, const Mesh& refined,
                           const ProjectiveTexture& refined_texture,
                           const std::vector<unsigned char>& faces_to_measure,
                           const OpticalFlowOptions& options, const std::string& where,
                           FlowFields* fields = nullptr);

}  // namespace finecap

#endif  // FINECAP_EVAL_FLOW_EVALUATION_H_
