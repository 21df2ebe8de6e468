#include "finecap/refine.h"

#include <chrono>

#include "finecap/error.h"
#include "finecap/frame_energy.h"
#include "finecap/render.h"

namespace finecap {
namespace {

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::vector<int> FineMaskIds(const SubdivisionStencil& stencil, const std::vector<int>& coarse_mask,
                             int num_coarse_vertices) {
  std::vector<int> ids;
  if (coarse_mask.empty()) {
    for (int v = 0; v < stencil.num_fine_vertices(); ++v) ids.push_back(v);
    return ids;
  }
  std::vector<bool> coarse(num_coarse_vertices, false);
  for (int v : coarse_mask) coarse[v] = true;
  const std::vector<bool> fine = SubdivideVertexMask(stencil, coarse);
  for (int v = 0; v < static_cast<int>(fine.size()); ++v) {
    if (fine[v]) ids.push_back(v);
  }
  return ids;
}

}  // namespace

void RefineOptions::Check() const {
  Require(subdivision_levels >= 0 && subdivision_levels <= 4, "model.subdivision_levels",
          "must lie in [0, 4]");
  Require(sigma_hat > 0.0, "model.sigma_hat", "must be positive");
  image.Check();
  visibility.Check();
  energy.Check();
  solver.Check();
}

SequenceModel::SequenceModel(const Mesh& first_coarse, const std::vector<int>& coarse_mask,
                             const RefineOptions& options, const std::string& where)
    : stencil_(BuildLoopSubdivision(first_coarse, options.subdivision_levels, where)) {
  refined_vertices_ = FineMaskIds(stencil_, coarse_mask, first_coarse.num_vertices());
  const Mesh fine = ApplySubdivision(stencil_, first_coarse.vertices);
  neighbourhoods_ = BuildVertexNeighbourhoods(fine, options.energy.reg_rings, where);
}

Mesh SequenceModel::Subdivide(const Mesh& coarse) const {
  return ApplySubdivision(stencil_, coarse.vertices);
}

std::vector<std::vector<unsigned char>> ComputeFrameVisibility(const Mesh& mesh,
                                                               const Eigen::Matrix3Xd& normals,
                                                               const std::vector<Camera>& cameras,
                                                               const VisibilityOptions& options) {
  std::vector<std::vector<unsigned char>> visible(cameras.size());
  for (size_t c = 0; c < cameras.size(); ++c) {
    const DepthMap depth = RenderDepth(cameras[c], mesh);
    visible[c] = ComputeVisibility(cameras[c], depth.depth, mesh.vertices, normals, options);
  }
  return visible;
}

ReferenceColors ComputeSequenceColors(const SequenceModel& model, const FrameInput& reference,
                                      const RefineOptions& options) {
  const Mesh fine = model.Subdivide(reference.coarse);
  const Eigen::Matrix3Xd normals = ComputeVertexNormals(fine);
  const auto visible = ComputeFrameVisibility(fine, normals, reference.cameras, options.visibility);
  return ComputeReferenceColors(fine.vertices, normals, reference.cameras, reference.images,
                                visible, options.image.color_space, options.sigma_hat);
}

FrameResult RefineFrame(const SequenceModel& model, const ReferenceColors& colors,
                        const FrameInput& input, const RefineOptions& options,
                        const Eigen::VectorXd* warm_start) {
  const auto start = std::chrono::steady_clock::now();
  FrameResult result;
  const Mesh fine = model.Subdivide(input.coarse);
  const Eigen::Matrix3Xd normals = ComputeVertexNormals(fine);
  const auto visible = ComputeFrameVisibility(fine, normals, input.cameras, options.visibility);

  std::vector<std::string> names;
  for (const Camera& camera : input.cameras) names.push_back(camera.name);
  const std::vector<ImageGaussians> images =
      BuildFrameImageGaussians(input.images, {}, options.image, names);

  SurfaceGaussians surface =
      MakeSurfaceGaussians(fine.vertices, normals, model.refined_vertices(), colors);
  std::vector<CameraInput> cameras(input.cameras.size());
  for (size_t c = 0; c < cameras.size(); ++c) {
    cameras[c].camera = input.cameras[c];
    cameras[c].image = &images[c];
    for (int v : surface.vertex_ids) cameras[c].visible.push_back(visible[c][v]);
    result.num_image_gaussians += images[c].size();
  }
  result.num_surface_gaussians = surface.size();
  FrameEnergy energy(std::move(surface), cameras, model.neighbourhoods(), options.energy);
  result.num_pairs = energy.num_pairs();
  result.seconds_preparation = SecondsSince(start);

  Eigen::VectorXd k = Eigen::VectorXd::Zero(energy.num_parameters());
  if (warm_start != nullptr && warm_start->size() == k.size()) k = *warm_start;
  result.summary = Solve(&energy, options.solver, &k);
  result.k_solved = k;
  result.worse = result.summary.energy_end < result.summary.energy_start;
  result.kept_input = result.worse && options.keep_input_if_worse;

  const double bias = options.bias_compensation ? options.sigma_hat : 0.0;
  result.refined = fine;
  result.k = Eigen::VectorXd::Constant(fine.num_vertices(), std::nan(""));
  const std::vector<int>& ids = energy.surface().vertex_ids;
  for (size_t s = 0; s < ids.size(); ++s) {
    const double displacement = result.kept_input ? 0.0 : k[s] + bias;
    result.k[ids[s]] = displacement;
    result.refined.vertices.col(ids[s]) += displacement * normals.col(ids[s]);
  }
  result.normals = ComputeVertexNormals(result.refined);
  result.seconds_total = SecondsSince(start);
  return result;
}

}  // namespace finecap
