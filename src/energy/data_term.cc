#include "finecap/energy/data_term.h"

namespace finecap {

void DataTerm::BlockCosts(const Eigen::VectorXd& k, std::vector<double>* costs) {
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

Eigen::VectorXd DataTerm::GaussNewtonDiagonal(const Eigen::VectorXd& k) {
  PrepareResiduals(k, true);
  Eigen::VectorXd curvature = Eigen::VectorXd::Zero(k.size());
  std::vector<double> residuals, jacobian;
  const auto& blocks = residual_blocks();
  for (int b = 0; b < static_cast<int>(blocks.size()); ++b) {
    const int num_parameters = static_cast<int>(blocks[b].parameters.size());
    residuals.resize(blocks[b].num_residuals);
    jacobian.resize(blocks[b].num_residuals * num_parameters);
    BlockResiduals(b, residuals.data(), jacobian.data());
    for (int r = 0; r < blocks[b].num_residuals; ++r) {
      for (int p = 0; p < num_parameters; ++p) {
        const double derivative = jacobian[r * num_parameters + p];
        curvature[blocks[b].parameters[p]] += derivative * derivative;
      }
    }
  }
  return curvature;
}

void DataTerm::BlockCostsAround(const Eigen::VectorXd& base, const Eigen::VectorXd& displacements,
                                Eigen::MatrixXd* costs) {
  costs->resize(static_cast<Eigen::Index>(residual_blocks().size()), displacements.size());
  std::vector<double> block_costs;
  for (int j = 0; j < displacements.size(); ++j) {
    BlockCosts((base.array() + displacements[j]).matrix(), &block_costs);
    costs->col(j) = Eigen::Map<const Eigen::VectorXd>(block_costs.data(), costs->rows());
  }
}

void SummarisedDataTerm::UniformBlockCosts(int num_unknowns, const Eigen::VectorXd& displacements,
                                           Eigen::MatrixXd* costs) {
  BlockCostsAround(Eigen::VectorXd::Zero(num_unknowns), displacements, costs);
}

BlockSummary SummarisedDataTerm::Summarise(const double* residuals, const double* jacobian, int m) {
  BlockSummary summary;
  for (int r = 0; r < m; ++r) {
    summary.squared_norm += residuals[r] * residuals[r];
    summary.gradient += jacobian[r] * residuals[r];
    summary.curvature += jacobian[r] * jacobian[r];
  }
  return summary;
}

void SummarisedDataTerm::PrepareBlockSummaries(const Eigen::VectorXd& k) {
  PrepareResiduals(k, true);
  const int num_blocks = static_cast<int>(residual_blocks().size());
  summaries_.resize(num_blocks);
#pragma omp parallel
  {
    std::vector<double> residuals, jacobian;
#pragma omp for schedule(dynamic, 256)
    for (int b = 0; b < num_blocks; ++b) {
      const ResidualBlock& block = residual_blocks()[b];
      if (block.parameters.size() != 1) continue;
      residuals.resize(block.num_residuals);
      jacobian.resize(block.num_residuals);
      BlockResiduals(b, residuals.data(), jacobian.data());
      summaries_[b] = Summarise(residuals.data(), jacobian.data(), block.num_residuals);
    }
  }
}

}  // namespace finecap
