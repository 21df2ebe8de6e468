#include "finecap/scene_scale.h"

#include <sstream>

#include "finecap/error.h"

namespace finecap {

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
  Require(sigma_hat > 0.0, "model.sigma_hat", "must be positive");
  const double diagonal = BoundingBoxDiagonal(mesh);
  const double sigmas = diagonal / sigma_hat;
  if (sigmas >= limits.min_sigmas && sigmas <= limits.max_sigmas) return;
  std::ostringstream problem;
  problem.precision(4);
  problem << "the coarse mesh measures " << diagonal << " across (bounding-box diagonal), "
          << sigmas << " times model.sigma_hat = " << sigma_hat << "; finecap's lengths are metres";
  if (sigmas > limits.max_sigmas) {
    problem << ", and a mesh this large looks like one in millimetres or centimetres: convert the "
               "capture (meshes and camera translations) to metres, or raise model.sigma_hat for "
               "a subject larger than "
            << limits.max_sigmas * sigma_hat << " m";
  } else {
    problem << ", and a mesh this small is too small for the surface Gaussians (or in a larger "
               "unit than metres): convert the capture to metres, or lower model.sigma_hat (and "
               "energy.k_max) for a subject smaller than "
            << limits.min_sigmas * sigma_hat << " m";
  }
  throw Error(where, problem.str());
}

}  // namespace finecap
