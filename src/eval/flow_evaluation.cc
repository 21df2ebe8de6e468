#include "finecap/eval/flow_evaluation.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "finecap/geometry/render.h"
#include "finecap/model/visibility.h"
#include "finecap/util/error.h"

namespace finecap {
namespace {

constexpr char kWhere[] = "flow evaluation";

// The camera that sees all corners of `face` most frontally, or -1 when none sees them all.
int BestCameraOfFace(const Mesh& mesh, const Eigen::Matrix3Xd& normals, int face,
                     const std::vector<Camera>& cameras,
                     const std::vector<std::vector<unsigned char>>& visible) {
  const Eigen::Vector3i corners = mesh.faces.col(face);
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  for (int i = 0; i < 3; ++i) {
    centre += mesh.vertices.col(corners[i]) / 3.0;
    normal += normals.col(corners[i]);
  }
  return MostFrontalCamera(centre, normal, cameras, [&](int c) {
    return visible[c][corners[0]] && visible[c][corners[1]] && visible[c][corners[2]];
  });
}

// The images side by side (top-aligned, black below a shorter one); `offsets[c]` receives the
// column where image c starts.
cv::Mat MakeAtlas(const std::vector<cv::Mat>& images, std::vector<int>* offsets) {
  int width = 0;
  int height = 0;
  for (const cv::Mat& image : images) {
    offsets->push_back(width);
    width += image.cols;
    height = std::max(height, image.rows);
  }
  cv::Mat atlas(height, width, CV_8UC3, cv::Scalar::all(0));
  for (size_t c = 0; c < images.size(); ++c) {
    images[c].copyTo(atlas(cv::Rect((*offsets)[c], 0, images[c].cols, images[c].rows)));
  }
  return atlas;
}

void RequireTextureInputs(const Mesh& mesh, const Eigen::Matrix3Xd& normals,
                          const std::vector<Camera>& cameras, const std::vector<cv::Mat>& images,
                          const std::vector<std::vector<unsigned char>>& visible) {
  Require(!cameras.empty() && images.size() == cameras.size() && visible.size() == cameras.size(),
          kWhere, "needs one image and one visibility list per camera");
  Require(normals.cols() == mesh.num_vertices(), kWhere, "needs one normal per vertex");
  for (size_t c = 0; c < cameras.size(); ++c) {
    Require(images[c].type() == CV_8UC3 && images[c].cols == cameras[c].width &&
                images[c].rows == cameras[c].height,
            kWhere, "image of camera " + cameras[c].name + " is not 8-bit BGR of its size");
    Require(static_cast<int>(visible[c].size()) == mesh.num_vertices(), kWhere,
            "visibility of camera " + cameras[c].name + " is not one flag per vertex");
  }
}

}  // namespace

ProjectiveTexture MakeProjectiveTexture(const Mesh& mesh, const Eigen::Matrix3Xd& normals,
                                        const std::vector<Camera>& cameras,
                                        const std::vector<cv::Mat>& images,
                                        const std::vector<std::vector<unsigned char>>& visible) {
  RequireTextureInputs(mesh, normals, cameras, images, visible);
  ProjectiveTexture texture;
  std::vector<int> offsets;
  texture.atlas = MakeAtlas(images, &offsets);
  const Eigen::Vector2d size(texture.atlas.cols, texture.atlas.rows);
  texture.corner_uvs =
      Eigen::Matrix2Xd::Constant(2, 3 * mesh.num_faces(), 0.5).array().colwise() / size.array();
  texture.textured.assign(mesh.num_faces(), 0);
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const int c = BestCameraOfFace(mesh, normals, f, cameras, visible);
    if (c < 0) continue;
    texture.textured[f] = 1;
    for (int i = 0; i < 3; ++i) {
      // Pixel centres sit at integer coordinates, texel centres at (x + 0.5) / width.
      const Eigen::Vector2d pixel = cameras[c].Project(mesh.vertices.col(mesh.faces(i, f)));
      const Eigen::Vector2d texel(offsets[c] + pixel.x() + 0.5, pixel.y() + 0.5);
      texture.corner_uvs.col(3 * f + i) = texel.cwiseQuotient(size);
    }
  }
  return texture;
}

void FillUntexturedFaces(const ProjectiveTexture& fallback, ProjectiveTexture* texture) {
  Require(fallback.textured.size() == texture->textured.size() &&
              fallback.corner_uvs.cols() == texture->corner_uvs.cols() &&
              fallback.atlas.size() == texture->atlas.size(),
          kWhere, "the fallback texture was made for another mesh or other images");
  for (size_t f = 0; f < texture->textured.size(); ++f) {
    if (texture->textured[f] || !fallback.textured[f]) continue;
    texture->textured[f] = 1;
    texture->corner_uvs.middleCols<3>(3 * f) = fallback.corner_uvs.middleCols<3>(3 * f);
  }
}

std::vector<unsigned char> FacesToMeasure(const Mesh& mesh, const ProjectiveTexture& texture,
                                          const std::vector<int>& vertex_ids) {
  Require(static_cast<int>(texture.textured.size()) == mesh.num_faces(), kWhere,
          "the texture was made for another mesh");
  std::vector<unsigned char> chosen(mesh.num_vertices(), 0);
  for (int v : vertex_ids) {
    Require(v >= 0 && v < mesh.num_vertices(), kWhere, "vertex id out of range");
    chosen[v] = 1;
  }
  std::vector<unsigned char> faces(mesh.num_faces(), 0);
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const bool touches =
        chosen[mesh.faces(0, f)] || chosen[mesh.faces(1, f)] || chosen[mesh.faces(2, f)];
    faces[f] = texture.textured[f] && touches;
  }
  return faces;
}

cv::Mat RenderTexturedOverImage(const Camera& camera, const Mesh& mesh,
                                const ProjectiveTexture& texture, const cv::Mat& image) {
  RenderOptions options;
  options.supersampling = 1;  // The texture is at image resolution; the seen face decides.
  SurfaceAppearance appearance;
  appearance.corner_uvs = texture.corner_uvs;
  appearance.texture = texture.atlas;
  cv::Mat render = RenderColor(camera, mesh, appearance, options);
  const cv::Mat no_surface = RenderDepth(camera, mesh, options).triangle_ids < 0;
  image.copyTo(render, no_surface);
  return render;
}

namespace {

// Pixels whose nearest face in `mesh` is one to measure.
cv::Mat MeasuredPixels(const Camera& camera, const Mesh& mesh,
                       const std::vector<unsigned char>& faces_to_measure) {
  const cv::Mat ids = RenderDepth(camera, mesh).triangle_ids;
  cv::Mat mask(ids.size(), CV_8UC1, cv::Scalar(0));
  for (int y = 0; y < ids.rows; ++y) {
    for (int x = 0; x < ids.cols; ++x) {
      const int face = ids.at<int>(y, x);
      if (face >= 0 && faces_to_measure[face]) mask.at<unsigned char>(y, x) = 255;
    }
  }
  return mask;
}

}  // namespace

FlowComparison CompareFlow(const Camera& camera, const cv::Mat& image, const Mesh& coarse,
                           const ProjectiveTexture& coarse_texture, const Mesh& refined,
                           const ProjectiveTexture& refined_texture,
                           const std::vector<unsigned char>& faces_to_measure,
                           const OpticalFlowOptions& options, const std::string& where,
                           FlowFields* fields) {
  Require(image.cols == camera.width && image.rows == camera.height, where,
          "the image is not of camera " + camera.name + "'s size");
  Require(static_cast<int>(faces_to_measure.size()) == coarse.num_faces() &&
              refined.num_faces() == coarse.num_faces() &&
              coarse_texture.textured.size() == faces_to_measure.size() &&
              refined_texture.textured.size() == faces_to_measure.size(),
          where,
          "the meshes, their textures and the faces to measure disagree in their face count");
  const cv::Mat mask = MeasuredPixels(camera, coarse, faces_to_measure) |
                       MeasuredPixels(camera, refined, faces_to_measure);
  const cv::Mat coarse_flow = ComputeOpticalFlow(
      RenderTexturedOverImage(camera, coarse, coarse_texture, image), image, options, where);
  const cv::Mat refined_flow = ComputeOpticalFlow(
      RenderTexturedOverImage(camera, refined, refined_texture, image), image, options, where);
  if (fields) *fields = FlowFields{mask, coarse_flow, refined_flow};
  return {SumFlowMagnitude(coarse_flow, mask, where), SumFlowMagnitude(refined_flow, mask, where)};
}

double FlowImprovementPercent(double coarse_px, double refined_px) {
  if (!(std::isfinite(coarse_px) && coarse_px > 0.0))
    return std::numeric_limits<double>::quiet_NaN();
  return 100.0 * (coarse_px - refined_px) / coarse_px;
}

}  // namespace finecap
