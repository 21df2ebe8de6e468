// The paper's smoothness term (eq. 9):
//
//   E_reg = sum_s sum_{j in Psi(s)} T(delta_sj) * (u * (k_s - k_j))^2,
//
// over the vertices within Delta edges (neighbourhood.h), with Wendland weights T of the edge
// distance (cut-off Delta) and u the unit of k inside E_reg (1000 for millimetres, the paper's
// lengths). Note that with the paper's Delta = 2, T(2) = 0: only the one-ring carries weight
// (T(1) = 3/16). A neighbour that has no surface Gaussian (outside the mask, or seen by no
// camera) keeps k = 0, so the refined region joins the unrefined one smoothly.
#ifndef FINECAP_REGULARIZER_H_
#define FINECAP_REGULARIZER_H_

#include <vector>

#include <Eigen/Core>

#include "finecap/geometry/neighbourhood.h"

namespace finecap {

class Regularizer {
 public:
  // One unordered pair of neighbours with a non-zero weight T(delta). `b` is -1 when the
  // neighbour is fixed at k = 0.
  struct Pair {
    int a = 0;
    int b = -1;
    double weight = 0.0;
  };

  // `vertex_ids[s]` is the mesh vertex of surface Gaussian s; `neighbourhoods` are over all mesh
  // vertices (built with cut-off `rings` = Delta); `unit_scale` is u.
  Regularizer(const VertexNeighbourhoods& neighbourhoods, const std::vector<int>& vertex_ids,
              int rings, double unit_scale);

  // E_reg at k, and dE_reg/dk when `gradient` is not null.
  double Evaluate(const Eigen::VectorXd& k, Eigen::VectorXd* gradient) const;

  // Every unordered pair once; E_reg = 2 sum_pairs weight * (u * (k_a - k_b))^2.
  const std::vector<Pair>& pairs() const { return pairs_; }

  // Replaces, `rounds` times, each row of `values` (one per surface Gaussian) by the mean of its
  // own and those of its neighbours with a non-zero weight; fixed neighbours do not count.
  void AverageOverNeighbours(int rounds, Eigen::MatrixXd* values) const;
  double unit_scale() const { return unit_scale_; }

 private:
  std::vector<Pair> pairs_;
  double unit_scale_;
};

}  // namespace finecap

#endif  // FINECAP_REGULARIZER_H_
