#include "refine/surface_sampling.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <opencv2/imgproc.hpp>

#include "finecap/geometry/color.h"
#include "finecap/geometry/mesh_edges.h"
#include "finecap/util/error.h"
#include "finecap/util/threads.h"
#include "refine/foreground.h"
#include "refine/scene_scale.h"

namespace finecap {

int SampleSegments(const Mesh& mesh, const std::vector<Camera>& cameras, double spacing) {
  constexpr int kMaxSegments = 16;
  const SceneScale scale = MeasureSceneScale(mesh, cameras);
  const double target = spacing * scale.pixel_footprint;
  if (!(target > 0.0) || !(scale.mean_edge_length > target)) return 1;
  return static_cast<int>(
      std::min<double>(kMaxSegments, std::ceil(scale.mean_edge_length / target)));
}

Eigen::SparseMatrix<double> SplitFaces(const Mesh& mesh, int segments) {
  Require(segments >= 1, "SplitFaces", "at least one segment a side expected");
  const int n = segments, num_vertices = mesh.num_vertices();
  const MeshEdges edges = BuildMeshEdges(mesh.faces);
  const long num_edge_points = static_cast<long>(edges.num_edges()) * (n - 1);
  const long inside_per_face = static_cast<long>(n - 1) * (n - 2) / 2;
  const long num_inside_points = mesh.num_faces() * inside_per_face;
  const long num_points = num_vertices + num_edge_points + num_inside_points;
  Require(num_points <= std::numeric_limits<int>::max(), "SplitFaces",
          "the mesh split " + std::to_string(n) + " a side has more points than a sample id holds");
  std::vector<Eigen::Triplet<double>> weights;
  weights.reserve(num_vertices + 2 * num_edge_points + 3 * num_inside_points);
  for (int v = 0; v < num_vertices; ++v) weights.emplace_back(v, v, 1.0);
  int point = num_vertices;
  for (int e = 0; e < edges.num_edges(); ++e) {
    for (int i = 1; i < n; ++i, ++point) {
      weights.emplace_back(point, edges.vertices(0, e), double(n - i) / n);
      weights.emplace_back(point, edges.vertices(1, e), double(i) / n);
    }
  }
  // A face's inside points: corner weights (n - i - j, i, j) / n with none of them 0. A collapsed
  // face's repeated corner gets the sum of its weights (setFromTriplets adds duplicates).
  for (int f = 0; f < mesh.num_faces(); ++f) {
    for (int i = 1; i < n; ++i) {
      for (int j = 1; i + j < n; ++j, ++point) {
        weights.emplace_back(point, mesh.faces(0, f), double(n - i - j) / n);
        weights.emplace_back(point, mesh.faces(1, f), double(i) / n);
        weights.emplace_back(point, mesh.faces(2, f), double(j) / n);
      }
    }
  }
  Eigen::SparseMatrix<double> stencil(num_points, num_vertices);
  stencil.setFromTriplets(weights.begin(), weights.end());
  return stencil;
}

SurfaceSamples SampleSurface(const Mesh& mesh, const Eigen::Matrix3Xd& normals,
                             const SurfaceGaussians& surface,
                             const VertexNeighbourhoods& neighbourhoods, int patch_rings,
                             int segments) {
  const Eigen::SparseMatrix<double> stencil = SplitFaces(mesh, segments);
  SurfaceSamples samples;
  samples.base = mesh.vertices * stencil.transpose();
  samples.normals = (normals * stencil.transpose()).colwise().normalized();
  std::vector<int> surface_of_vertex(mesh.num_vertices(), -1);
  for (int s = 0; s < surface.size(); ++s) surface_of_vertex[surface.vertex_ids[s]] = s;

  // The stencil is column-major: column v lists the samples with a weight on vertex v.
  std::vector<Eigen::Triplet<double>> weights;
  for (int v = 0; v < stencil.outerSize(); ++v) {
    const int s = surface_of_vertex[v];
    if (s < 0) continue;
    for (Eigen::SparseMatrix<double>::InnerIterator it(stencil, v); it; ++it)
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
    for (Eigen::SparseMatrix<double>::InnerIterator it(stencil, v); it; ++it) {
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
  ParallelFor(static_cast<int>(images.size()), [&](int c) {
    images[c] = ConvertImage(images[c], space, input.cameras[c].name);
    if (blur > 0.0) cv::GaussianBlur(images[c], images[c], cv::Size(0, 0), blur);
  });
  return images;
}

}  // namespace finecap
