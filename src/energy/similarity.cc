#include "finecap/energy/similarity.h"

namespace finecap {

void SimilarityTerm::BlockCosts(const Eigen::VectorXd& k, std::vector<double>* costs) {
  PrepareResiduals(k, false);
  const int num_blocks = static_cast<int>(residual_blocks().size());
  costs->resize(num_blocks);
#pragma omp parallel
  {
    std::vector<double> residuals;
#pragma omp for schedule(dynamic, 256)
    for (int b = 0; b < num_blocks; ++b) {
      residuals.resize(residual_blocks()[b].num_residuals);
      BlockResiduals(b, residuals.data(), nullptr);
      double cost = 0.0;
      for (double r : residuals) cost += r * r;
      (*costs)[b] = cost;
    }
  }
}

}  // namespace finecap
