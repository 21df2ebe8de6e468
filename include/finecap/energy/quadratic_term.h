// The terms of a frame's energy that are quadratic in the displacements k: every term but the
// similarity (the smoothness of the paper's eq. 9, the pull towards the input, the pull towards
// the frame before). Each adds what it is made of, in two kinds of pieces:
//
//  * pulls of one unknown towards a target, 1/2 p_s (k_s - t_s)^2;
//  * differences of two neighbours, 1/2 c^2 (k_a - k_b)^2, with k_b = 0 for a neighbour held at
//    the input (b = -1).
//
// The frame's energy (frame_energy.h) gathers the pieces of all its terms, so that a solver meets
// one quadratic part whatever terms made it: a least-squares solver takes the pieces as residual
// rows (sqrt(p_s) (k_s - t_s) and c (k_a - k_b)), the others the energy and gradient. A new
// quadratic term is a class of this interface in its own folder (src/energy/terms/) and a line of
// the registry (src/energy/term_registry.cc): the solvers do not change.
#ifndef FINECAP_ENERGY_QUADRATIC_TERM_H_
#define FINECAP_ENERGY_QUADRATIC_TERM_H_

#include <functional>
#include <vector>

#include <Eigen/Core>

#include "finecap/energy/energy_options.h"
#include "finecap/model/surface_gaussians.h"

namespace finecap {

class Regularizer;

// The pulls on each unknown, E_pull = 1/2 sum_s p_s (k_s - t_s)^2. Two pulls on one k_s are one
// quadratic: their curvatures add and their targets blend by them (and a constant, which no
// solver needs, is dropped).
class Pulls {
 public:
  // No pull on any of `num_unknowns` unknowns.
  explicit Pulls(int num_unknowns = 0)
      : curvature_(Eigen::VectorXd::Zero(num_unknowns)),
        target_(Eigen::VectorXd::Zero(num_unknowns)) {}

  // Adds 1/2 curvature_s (k_s - target_s)^2 for every s where curvature_s is positive and
  // target_s finite (a term may have no target for an unknown). Where no pull was yet, the new one
  // is taken as it is.
  void Add(const Eigen::VectorXd& curvature, const Eigen::VectorXd& target);
  // As Add, with the same curvature for every s.
  void Add(double curvature, const Eigen::VectorXd& target);

  // p_s and t_s (0 where nothing pulls).
  const Eigen::VectorXd& curvature() const { return curvature_; }
  const Eigen::VectorXd& target() const { return target_; }
  // E_pull at k; its gradient is p_s (k_s - t_s).
  double Evaluate(const Eigen::VectorXd& k) const;

 private:
  Eigen::VectorXd curvature_;
  Eigen::VectorXd target_;
};

// One difference of neighbours, E = 1/2 (root (k_a - k_b))^2.
struct Difference {
  int a = 0;
  int b = -1;  // -1: the neighbour is held at the input, k_b = 0.
  double root = 0.0;
};

// What a quadratic term may read of its frame as it is built.
struct TermContext {
  const SurfaceGaussians& surface;
  const EnergyOptions& options;
  // The mesh neighbours of the surface Gaussians with the paper's weights (regularizer.h).
  const Regularizer& neighbours;
  // How sure the images are of each k_s, in [0, 1] (input_prior.h, Confidence).
  const Eigen::VectorXd& confidence;
  // H, the median of the positive data curvatures at the input surface: a typical data term's
  // hold on one unknown, so that a pull can be stated in the data's own units. Measured on first
  // call (a pass over the similarity's residuals), then kept.
  std::function<double()> typical_data_curvature;
};

class QuadraticTerm {
 public:
  virtual ~QuadraticTerm() = default;

  // Adds the term's pulls to *pulls (none by default).
  virtual void AddPulls(Pulls* /*pulls*/) const {}

  // Adds the term's differences to *differences (none by default), and their part of the energy,
  // 1/2 sum root^2 (k_a - k_b)^2, at k, with its gradient added to *gradient when not null.
  virtual void AddDifferences(std::vector<Difference>* /*differences*/) const {}
  virtual double DifferenceEnergy(const Eigen::VectorXd& /*k*/,
                                  Eigen::VectorXd* /*gradient*/) const {
    return 0.0;
  }

  // For a term that reads the solution of the frame before, one displacement per surface
  // Gaussian (NaN where that frame has none): takes it, and returns true when its pulls changed.
  // The solution is known only after the frame before is solved, which may be after this frame's
  // energy is built (frames are prepared ahead).
  virtual bool TakeFrameBefore(const Eigen::VectorXd& /*k_before*/) { return false; }
};

}  // namespace finecap

#endif  // FINECAP_ENERGY_QUADRATIC_TERM_H_
