// The energy of one frame, E(k) = E_sim(k) - w_reg * E_reg(k) (the paper's eq. 3) - E_prior(k)
// (input_prior.h; zero unless configured), built from the
// surface Gaussians, the cameras with their image Gaussians and visibility, and the mesh's
// neighbourhoods. It owns the pair lists, so it is built once per frame and then evaluated many
// times by a solver; it is neither copied nor moved (the terms refer to its members).
#ifndef FINECAP_FRAME_ENERGY_H_
#define FINECAP_FRAME_ENERGY_H_

#include <memory>
#include <vector>

#include <Eigen/Core>

#include "finecap/energy/energy_options.h"
#include "finecap/energy/regularizer.h"
#include "finecap/energy/similarity.h"
#include "finecap/geometry/neighbourhood.h"
#include "finecap/model/gaussian_pairs.h"
#include "finecap/model/surface_gaussians.h"

namespace finecap {

// One camera of a frame: its pinhole camera, the image Gaussians of its image (not owned), and
// which surface Gaussians it sees (one flag per surface Gaussian).
struct CameraInput {
  Camera camera;
  const ImageGaussians* image = nullptr;
  std::vector<unsigned char> visible;
};

// The options of the pair lists the energy builds with `options` (gaussian_pairs.h).
PairOptions EnergyPairOptions(const EnergyOptions& options);

class FrameEnergy {
 public:
  // `neighbourhoods` are over the mesh vertices (built with options.reg_rings).
  FrameEnergy(SurfaceGaussians surface, const std::vector<CameraInput>& cameras,
              const VertexNeighbourhoods& neighbourhoods, const EnergyOptions& options);
  FrameEnergy(const FrameEnergy&) = delete;
  FrameEnergy& operator=(const FrameEnergy&) = delete;

  int num_parameters() const { return surface_.size(); }
  const SurfaceGaussians& surface() const { return surface_; }
  const EnergyOptions& options() const { return options_; }
  // The cameras' pair lists, without their image Gaussian ids, and without the image Gaussians
  // themselves (EnergyView::image null), when the similarity does not read them after it is built
  // (SimilarityTerm::ReadsPairLists): the image models may then go.
  const std::vector<EnergyView>& views() const { return views_; }
  SimilarityTerm& similarity() { return *similarity_; }
  const SimilarityTerm& similarity() const { return *similarity_; }
  const Regularizer& regularizer() const { return regularizer_; }
  // p_s of E_prior = 1/2 sum_s p_s k_s^2 (input_prior.h), one entry per surface Gaussian.
  const Eigen::VectorXd& prior_curvature() const { return prior_curvature_; }
  // Evaluated pairs of Gaussians, summed over cameras.
  long num_pairs() const;

  // E at k and, when `gradient` is not null, dE/dk. The parts go to the optional outputs.
  double Evaluate(const Eigen::VectorXd& k, Eigen::VectorXd* gradient, double* similarity = nullptr,
                  double* regularization = nullptr) const;

 private:
  SurfaceGaussians surface_;
  EnergyOptions options_;
  std::vector<EnergyView> views_;
  std::unique_ptr<SimilarityTerm> similarity_;
  Regularizer regularizer_;
  Eigen::VectorXd prior_curvature_;
  long num_pairs_ = 0;
};

}  // namespace finecap

#endif  // FINECAP_FRAME_ENERGY_H_
