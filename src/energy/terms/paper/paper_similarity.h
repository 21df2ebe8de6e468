// The paper's similarity, exactly as printed (Robertini et al. 2014, eq. 6-8):
//
//   E_sim = 1/n_c sum_c sum_{i in I(c)} min( sum_s T(|eta_i - eta_s|) E_is , E_ii ) / E_ii,
//
// with E_is the closed-form overlap (gaussian_overlap.h) and E_ii = pi sigma_i^2. The min() is the
// paper's occlusion handling: an image patch cannot be explained more than once. Its gradient
// sums dE_is/dk_s / E_ii over the image Gaussians whose min() is not clamped.
//
// Least-squares form (one residual per image Gaussian any surface Gaussian reaches):
//   r_ci = (1 - min(sum_s T E_is / E_ii, 1)) / sqrt(n_c),
// so that sum r_ci^2 is zero exactly when every reached patch is fully explained.
#ifndef FINECAP_PAPER_SIMILARITY_H_
#define FINECAP_PAPER_SIMILARITY_H_

#include <vector>

#include "finecap/energy/data_term.h"
#include "finecap/model/gaussian_overlap.h"
#include "finecap/model/surface_gaussians.h"

namespace finecap {

class PaperSimilarity : public SummarisedDataTerm {
 public:
  // `views` must have been built with colour weights (PairOptions::color_cutoff > 0); both
  // arguments must outlive this object.
  PaperSimilarity(const SurfaceGaussians& surface, const std::vector<EnergyView>& views,
                  OverlapForm form);

  double Evaluate(const Eigen::VectorXd& k, Eigen::VectorXd* gradient) const override;
  const std::vector<ResidualBlock>& residual_blocks() const override { return blocks_; }
  void PrepareResiduals(const Eigen::VectorXd& k, bool with_jacobians) override;
  void BlockResiduals(int block, double* residuals, double* jacobian) const override;

 private:
  // Per pair of one camera: T * E_is and T * dE_is/dk_s; per image Gaussian: sum_s T * E_is.
  struct CameraOverlaps {
    std::vector<double> overlap;
    std::vector<double> derivative;
    std::vector<double> sums;
  };
  void ComputeOverlaps(int camera, const Eigen::VectorXd& k, bool with_derivatives,
                       CameraOverlaps* overlaps) const;

  const SurfaceGaussians& surface_;
  const std::vector<EnergyView>& views_;
  OverlapForm form_;

  // Least-squares structure: block b is image Gaussian block_image_[b] of camera block_camera_[b];
  // its parameters come from the pairs block_pairs_[block_pair_begin_[b] ..).
  std::vector<ResidualBlock> blocks_;
  std::vector<int> block_camera_, block_image_, block_pair_begin_, block_pairs_;
  std::vector<double> residuals_, jacobians_;  // Jacobian entries in block_pairs_ order.
};

}  // namespace finecap

#endif  // FINECAP_PAPER_SIMILARITY_H_
