#include "refine/surface_sampling.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "finecap/geometry/color.h"
#include "finecap/geometry/subdivision.h"
#include "refine/foreground.h"
#include "refine/scene_scale.h"

namespace finecap {

int SampleLevels(const Mesh& mesh, const std::vector<Camera>& cameras, double spacing) {
  constexpr int kMaxLevels = 4;
  const SceneScale scale = MeasureSceneScale(mesh, cameras);
  const double target = spacing * scale.pixel_footprint;
  if (!(target > 0.0) || !(scale.mean_edge_length > target)) return 0;
  return std::min(kMaxLevels,
                  static_cast<int>(std::ceil(std::log2(scale.mean_edge_length / target))));
}

SurfaceSamples SampleSurface(const Mesh& mesh, const Eigen::Matrix3Xd& normals,
                             const SurfaceGaussians& surface,
                             const VertexNeighbourhoods& neighbourhoods, int patch_rings,
                             int levels) {
  const SubdivisionStencil stencil = BuildLinearSubdivision(mesh, levels);
  SurfaceSamples samples;
  samples.base = mesh.vertices * stencil.matrix.transpose();
  samples.normals = (normals * stencil.matrix.transpose()).colwise().normalized();
  std::vector<int> surface_of_vertex(mesh.num_vertices(), -1);
  for (int s = 0; s < surface.size(); ++s) surface_of_vertex[surface.vertex_ids[s]] = s;

  // The stencil is column-major: column v lists the samples with a weight on vertex v.
  std::vector<Eigen::Triplet<double>> weights;
  for (int v = 0; v < stencil.matrix.outerSize(); ++v) {
    const int s = surface_of_vertex[v];
    if (s < 0) continue;
    for (Eigen::SparseMatrix<double>::InnerIterator it(stencil.matrix, v); it; ++it)
      weights.emplace_back(static_cast<int>(it.row()), s, it.value());
  }
  samples.weights.resize(samples.size(), surface.size());
  samples.weights.setFromTriplets(weights.begin(), weights.end());

  // A patch: the samples on the faces around its vertex and around the vertices up to
  // patch_rings - 1 edges from it, the sample at the vertex itself (the same id, by the
  // stencil's numbering) first.
  samples.patches.resize(surface.size());
  std::vector<int> last_patch(samples.size(), -1);
  const auto add_samples_of = [&](int v, int s) {
    for (Eigen::SparseMatrix<double>::InnerIterator it(stencil.matrix, v); it; ++it) {
      const int j = static_cast<int>(it.row());
      if (last_patch[j] == s) continue;
      last_patch[j] = s;
      samples.patches[s].push_back(j);
    }
  };
  for (int s = 0; s < surface.size(); ++s) {
    const int v = surface.vertex_ids[s];
    last_patch[v] = s;
    samples.patches[s].push_back(v);
    add_samples_of(v, s);
    for (int e = neighbourhoods.offsets[v]; e < neighbourhoods.offsets[v + 1]; ++e) {
      if (neighbourhoods.edge_distances[e] < patch_rings)
        add_samples_of(neighbourhoods.neighbours[e], s);
    }
  }
  return samples;
}

std::vector<unsigned char> SampleVisibility(const SurfaceSamples& samples,
                                            const std::vector<unsigned char>& surface_visible) {
  std::vector<unsigned char> visible(samples.size(), 0);
  for (int j = 0; j < samples.size(); ++j) {
    Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(samples.weights, j);
    if (!it) continue;  // Blended from no surface Gaussian: in no patch.
    visible[j] = 1;
    for (; it; ++it) visible[j] &= surface_visible[it.col()];
  }
  return visible;
}

std::vector<cv::Mat> SampledImages(const FrameInput& input, ColorSpace space, double blur) {
  std::vector<cv::Mat> images = ForegroundImages(input);
  for (size_t c = 0; c < images.size(); ++c) {
    images[c] = ConvertImage(images[c], space, input.cameras[c].name);
    if (blur > 0.0) cv::GaussianBlur(images[c], images[c], cv::Size(0, 0), blur);
  }
  return images;
}

}  // namespace finecap
