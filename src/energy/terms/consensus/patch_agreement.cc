#include "energy/terms/consensus/patch_agreement.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

#include "finecap/util/error.h"

namespace finecap {
namespace internal {
namespace {

// Cauchy's loss rho(s) = c2 log(1 + s / c2) of a block's sum of squares s = |r|^2 as a scaling of
// its residuals r' = alpha r, alpha = sqrt(rho(s) / s), so that |r'|^2 = rho(s): a block that
// disagrees far more than c2 stops pulling its Gaussian harder, and the regulariser carries its
// neighbours' displacement into it. Then dr'/dk = alpha dr/dk + r (d alpha / ds) ds/dk.
struct CauchyScaling {
  double alpha = 1.0, dalpha_ds = 0.0;

  CauchyScaling(double c2, double s) {
    const double u = s / c2;
    // Below u ~ 1e-6 the closed forms lose digits; their Taylor series are exact to O(u^2) there.
    if (u < 1e-6) {
      alpha = 1.0 - 0.25 * u;
      dalpha_ds = -0.25 / c2;
    } else {
      const double rho = c2 * std::log1p(u);
      const double drho = 1.0 / (1.0 + u);
      alpha = std::sqrt(rho / s);
      dalpha_ds = (drho * s - rho) / (2.0 * alpha * s * s);
    }
  }
};

}  // namespace

void NormaliseColors(int n, double floor, bool pooled, double* q, double* inverse_deviation) {
  double mean[3] = {0.0, 0.0, 0.0}, variance[3] = {0.0, 0.0, 0.0};
  for (int m = 0; m < n; ++m) {
    for (int channel = 0; channel < 3; ++channel) mean[channel] += q[3 * m + channel];
  }
  for (double& value : mean) value /= n;
  for (int m = 0; m < n; ++m) {
    for (int channel = 0; channel < 3; ++channel) {
      const double difference = q[3 * m + channel] - mean[channel];
      variance[channel] += difference * difference;
    }
  }
  for (double& value : variance) value /= n;
  if (pooled) std::fill_n(variance, 3, (variance[0] + variance[1] + variance[2]) / 3.0);
  for (int channel = 0; channel < 3; ++channel) {
    inverse_deviation[channel] = 1.0 / std::sqrt(variance[channel] + floor * floor);
  }
  for (int m = 0; m < n; ++m) {
    for (int channel = 0; channel < 3; ++channel) {
      q[3 * m + channel] = (q[3 * m + channel] - mean[channel]) * inverse_deviation[channel];
    }
  }
}

void NormaliseDerivative(int n, bool pooled, const double* z, const double* inverse_deviation,
                         double* dq) {
  double mean_derivative[3] = {0.0, 0.0, 0.0}, z_dot_dq[3] = {0.0, 0.0, 0.0};
  for (int m = 0; m < n; ++m) {
    for (int channel = 0; channel < 3; ++channel) {
      mean_derivative[channel] += dq[3 * m + channel];
      z_dot_dq[channel] += z[3 * m + channel] * dq[3 * m + channel];
    }
  }
  for (int channel = 0; channel < 3; ++channel) {
    mean_derivative[channel] /= n;
    z_dot_dq[channel] /= n;
  }
  if (pooled) std::fill_n(z_dot_dq, 3, (z_dot_dq[0] + z_dot_dq[1] + z_dot_dq[2]) / 3.0);
  for (int m = 0; m < n; ++m) {
    for (int channel = 0; channel < 3; ++channel) {
      double& derivative = dq[3 * m + channel];
      derivative =
          (derivative - mean_derivative[channel] - z[3 * m + channel] * z_dot_dq[channel]) *
          inverse_deviation[channel];
    }
  }
}

void Normalise(int n, double floor, bool pooled, double* q, double* dq) {
  double inverse_deviation[3];
  NormaliseColors(n, floor, pooled, q, inverse_deviation);
  if (dq != nullptr) NormaliseDerivative(n, pooled, q, inverse_deviation, dq);
}

void AgainstCameraMean(int n, int num_cameras, const Eigen::Vector3d& weight, double* values,
                       const double* camera_weights) {
  const int stride = 3 * n;  // From one camera's patch to the next.
  // Per camera, its share of the mean and the factor of its values, once per patch rather than
  // once per member: a patch of samples has tens of members.
  thread_local std::vector<double> share, scale;
  share.resize(num_cameras);
  scale.resize(3 * num_cameras);
  const double total_weight =
      camera_weights != nullptr ? std::accumulate(camera_weights, camera_weights + num_cameras, 0.0)
                                : static_cast<double>(num_cameras);
  for (int a = 0; a < num_cameras; ++a) {
    const double camera_weight = camera_weights != nullptr ? camera_weights[a] : 1.0;
    share[a] = camera_weight / total_weight;
    const double root = std::sqrt(camera_weight);  // Exactly 1 for a camera of weight 1.
    for (int channel = 0; channel < 3; ++channel) scale[3 * a + channel] = root * weight[channel];
  }
  // Camera after camera, so that both loops run over contiguous values.
  thread_local std::vector<double> mean;
  mean.assign(stride, 0.0);
  for (int a = 0; a < num_cameras; ++a) {
    const double* camera_values = values + stride * a;
    for (int i = 0; i < stride; ++i) mean[i] += share[a] * camera_values[i];
  }
  for (int a = 0; a < num_cameras; ++a) {
    double* camera_values = values + stride * a;
    const double* camera_scale = &scale[3 * a];
    for (int m = 0; m < n; ++m) {
      for (int channel = 0; channel < 3; ++channel) {
        const int i = 3 * m + channel;
        camera_values[i] = camera_scale[channel] * (camera_values[i] - mean[i]);
      }
    }
  }
}

void AgreementResiduals(int n, int num_cameras, double floor, bool pooled,
                        const Eigen::Vector3d& weight, double* residuals, double* jacobian,
                        const double* camera_weights) {
  const int stride = 3 * n;
  for (int a = 0; a < num_cameras; ++a) {
    Normalise(n, floor, pooled, residuals + stride * a,
              jacobian != nullptr ? jacobian + stride * a : nullptr);
  }
  AgainstCameraMean(n, num_cameras, weight, residuals, camera_weights);
  if (jacobian != nullptr) AgainstCameraMean(n, num_cameras, weight, jacobian, camera_weights);
}

double ViewWeight(double view_cosine, double power) {
  // A view at grazing incidence keeps a little weight: its cosine is only as exact as the normal.
  constexpr double kMinCosine = 0.05;
  return power == 0.0 ? 1.0 : std::pow(std::max(std::abs(view_cosine), kMinCosine), power);
}

Eigen::Vector3d PatchContrast(int n, int num_cameras, const double* colors) {
  Eigen::Vector3d variance = Eigen::Vector3d::Zero();
  for (int a = 0; a < num_cameras; ++a) {
    const Eigen::Map<const Eigen::Matrix3Xd> camera_colors(&colors[3 * n * a], 3, n);
    const Eigen::Vector3d mean = camera_colors.rowwise().mean();
    variance += (camera_colors.colwise() - mean).cwiseAbs2().rowwise().mean();
  }
  return (variance / num_cameras).cwiseSqrt();
}

double AgreementLossScale(int n, int num_cameras, const Eigen::Vector3d& weight, double fraction) {
  return fraction * (3.0 * n * (num_cameras - 1) * weight.squaredNorm() / 3.0);
}

// Scales a block's residuals r (and their derivatives dr/dk, when given) by Cauchy's loss of
// scale c2 (none when c2 <= 0).
void Robustify(double c2, int num_residuals, double* residuals, double* jacobian) {
  if (c2 <= 0.0) return;
  double s = 0.0, ds = 0.0;
  for (int r = 0; r < num_residuals; ++r) {
    s += residuals[r] * residuals[r];
    if (jacobian != nullptr) ds += 2.0 * residuals[r] * jacobian[r];
  }
  const CauchyScaling scaling(c2, s);
  for (int r = 0; r < num_residuals; ++r) {
    if (jacobian != nullptr) {
      jacobian[r] = scaling.alpha * jacobian[r] + residuals[r] * scaling.dalpha_ds * ds;
    }
    residuals[r] *= scaling.alpha;
  }
}

// The summary of a block's residuals r' after Robustify from that of r before it, without
// either: with s = |r|^2, g = <r, dr/dk>, h = |dr/dk|^2 and a' = d alpha / dk = (d alpha / ds) 2g,
// |r'|^2 = alpha^2 s, <r', dr'/dk> = alpha^2 g + alpha a' s and
// |dr'/dk|^2 = alpha^2 h + 2 alpha a' g + a'^2 s.
// Without derivatives |r'|^2 = rho(s) alone, without alpha's square root and divisions.
BlockSummary Robustify(double c2, const BlockSummary& plain, bool with_derivatives) {
  if (c2 <= 0.0) return plain;
  if (!with_derivatives && plain.squared_norm >= 1e-6 * c2) {
    BlockSummary robust;
    robust.squared_norm = c2 * std::log1p(plain.squared_norm / c2);
    return robust;
  }
  const CauchyScaling scaling(c2, plain.squared_norm);
  const double alpha = scaling.alpha, dalpha_dk = scaling.dalpha_ds * 2.0 * plain.gradient;
  BlockSummary robust;
  robust.squared_norm = alpha * alpha * plain.squared_norm;
  robust.gradient = alpha * alpha * plain.gradient + alpha * dalpha_dk * plain.squared_norm;
  robust.curvature = alpha * alpha * plain.curvature + 2.0 * alpha * dalpha_dk * plain.gradient +
                     dalpha_dk * dalpha_dk * plain.squared_norm;
  return robust;
}

void Robustify(double c2, double* squared_norm, Eigen::VectorXd* gradient,
               Eigen::MatrixXd* curvature) {
  if (c2 <= 0.0) return;
  // As for one unknown, with a' = (d alpha / ds) 2 g a vector: the robust Jacobian is
  // alpha J + r a'^T, whose Gram matrix and product with alpha r these are.
  const CauchyScaling scaling(c2, *squared_norm);
  const double alpha = scaling.alpha, s = *squared_norm;
  const Eigen::VectorXd dalpha_dk = scaling.dalpha_ds * 2.0 * *gradient;
  if (curvature != nullptr) {
    const Eigen::MatrixXd cross = alpha * dalpha_dk * gradient->transpose();
    *curvature = alpha * alpha * *curvature + cross + cross.transpose() +
                 s * dalpha_dk * dalpha_dk.transpose();
  }
  *gradient = alpha * alpha * *gradient + alpha * s * dalpha_dk;
  *squared_norm = alpha * alpha * s;
}

}  // namespace internal

PatchAgreementTerm::PatchAgreementTerm(const ConsensusOptions& options, int num_cameras)
    : options_(options), scale_(1.0 / std::sqrt(static_cast<double>(std::max(num_cameras, 1)))) {
  options_.Check();
}

void PatchAgreementTerm::EndOfPass(const Eigen::VectorXd& k) {
  if (neighbours_ == nullptr) {
    SetPatchShape(k);
    return;
  }
  Eigen::MatrixXd shape = k;
  neighbours_->AverageOverNeighbours(options_.shape_smoothing_rounds, &shape);
  SetPatchShape(shape.col(0));
}

void PatchAgreementTerm::AddPatch(int parameter, const std::vector<int>& members,
                                  const std::vector<int>& cameras,
                                  const std::vector<double>& camera_weights) {
  Require(camera_weights.empty() == camera_weights_.empty() || blocks_.empty(), "consensus patches",
          "either every block's cameras are weighed or none");
  if (!camera_weights.empty()) {
    Require(camera_weights.size() == cameras.size(), "consensus patches",
            "one weight per camera of a patch expected");
    const double mean =
        std::accumulate(camera_weights.begin(), camera_weights.end(), 0.0) / cameras.size();
    Require(mean > 0.0, "consensus patches", "a patch's camera weights must not all be zero");
    for (double weight : camera_weights) camera_weights_.push_back(weight / mean);
  }
  members_.insert(members_.end(), members.begin(), members.end());
  patch_begin_.push_back(static_cast<int>(members_.size()));
  cameras_.insert(cameras_.end(), cameras.begin(), cameras.end());
  camera_begin_.push_back(static_cast<int>(cameras_.size()));
  blocks_.push_back({{parameter}, 3 * static_cast<int>(members.size() * cameras.size())});
  residual_begin_.push_back(residual_begin_.back() + blocks_.back().num_residuals);
}

void PatchAgreementTerm::WeighPatches() {
  weights_.resize(blocks_.size());
#pragma omp parallel for schedule(dynamic, 64)
  for (int b = 0; b < static_cast<int>(blocks_.size()); ++b) {
    std::vector<double> colors(3 * PatchSize(b) * NumCameras(b));
    PatchColors(b, 0.0, colors.data(), nullptr);
    weights_[b] = internal::PatchContrast(PatchSize(b), NumCameras(b), colors.data());
  }
}

void PatchAgreementTerm::PlainResiduals(int b, double k, double* residuals,
                                        double* jacobian) const {
  // The colours become the residuals in place.
  PatchColors(b, k, residuals, jacobian);
  internal::AgreementResiduals(PatchSize(b), NumCameras(b), options_.contrast_floor,
                               !options_.gain_per_channel, ResidualWeight(b), residuals, jacobian,
                               CameraWeights(b));
}

double PatchAgreementTerm::LossScale(int b) const {
  return internal::AgreementLossScale(PatchSize(b), NumCameras(b), ResidualWeight(b),
                                      options_.robust_fraction);
}

BlockSummary PatchAgreementTerm::SummaryAt(int b, double k, bool with_derivatives) const {
  thread_local std::vector<double> residuals, jacobian;
  const int num_residuals = blocks_[b].num_residuals;
  residuals.resize(num_residuals);
  jacobian.resize(with_derivatives ? num_residuals : 0);
  PlainResiduals(b, k, residuals.data(), with_derivatives ? jacobian.data() : nullptr);
  BlockSummary plain;
  if (with_derivatives) {
    plain = Summarise(residuals.data(), jacobian.data(), num_residuals);
  } else {
    for (int r = 0; r < num_residuals; ++r) plain.squared_norm += residuals[r] * residuals[r];
  }
  return internal::Robustify(LossScale(b), plain, with_derivatives);
}

double PatchAgreementTerm::Evaluate(const Eigen::VectorXd& k, Eigen::VectorXd* gradient) const {
  if (gradient != nullptr) *gradient = Eigen::VectorXd::Zero(k.size());
  const int num_blocks = static_cast<int>(blocks_.size());
  double sum_of_squares = 0.0;
#pragma omp parallel for schedule(dynamic, 64) reduction(+ : sum_of_squares)
  for (int b = 0; b < num_blocks; ++b) {
    const int s = blocks_[b].parameters[0];
    const BlockSummary summary = SummaryAt(b, k[s], gradient != nullptr);
    sum_of_squares += summary.squared_norm;
    // Each block owns one parameter: no two threads write the same entry.
    if (gradient != nullptr) (*gradient)[s] = -summary.gradient;
  }
  return -0.5 * sum_of_squares;
}

void PatchAgreementTerm::PrepareResiduals(const Eigen::VectorXd& k, bool with_jacobians) {
  residuals_.resize(residual_begin_.back());
  jacobians_.resize(with_jacobians ? residual_begin_.back() : 0);
  const int num_blocks = static_cast<int>(blocks_.size());
#pragma omp parallel for schedule(dynamic, 64)
  for (int b = 0; b < num_blocks; ++b) {
    double* residuals = &residuals_[residual_begin_[b]];
    double* jacobian = with_jacobians ? &jacobians_[residual_begin_[b]] : nullptr;
    PlainResiduals(b, k[blocks_[b].parameters[0]], residuals, jacobian);
    internal::Robustify(LossScale(b), blocks_[b].num_residuals, residuals, jacobian);
  }
}

Eigen::VectorXd PatchAgreementTerm::GaussNewtonDiagonal(const Eigen::VectorXd& k) {
  Eigen::VectorXd curvature = Eigen::VectorXd::Zero(k.size());
  const int num_blocks = static_cast<int>(blocks_.size());
#pragma omp parallel
  {
    std::vector<double> residuals, jacobian;
#pragma omp for schedule(dynamic, 64)
    for (int b = 0; b < num_blocks; ++b) {
      const int num_residuals = blocks_[b].num_residuals;
      residuals.resize(num_residuals);
      jacobian.resize(num_residuals);
      PlainResiduals(b, k[blocks_[b].parameters[0]], residuals.data(), jacobian.data());
      internal::Robustify(LossScale(b), num_residuals, residuals.data(), jacobian.data());
      // Each block owns one parameter: no two threads write the same entry.
      double& sum = curvature[blocks_[b].parameters[0]];
      for (int r = 0; r < num_residuals; ++r) sum += jacobian[r] * jacobian[r];
    }
  }
  return curvature;
}

void PatchAgreementTerm::BlockResiduals(int block, double* residuals, double* jacobian) const {
  const long begin = residual_begin_[block];
  const int num_residuals = blocks_[block].num_residuals;
  std::copy_n(&residuals_[begin], num_residuals, residuals);
  if (jacobian != nullptr) std::copy_n(&jacobians_[begin], num_residuals, jacobian);
}

void PatchAgreementTerm::PrepareBlockSummaries(const Eigen::VectorXd& k) {
  const int num_blocks = static_cast<int>(blocks_.size());
  summaries_.resize(num_blocks);
#pragma omp parallel for schedule(dynamic, 64)
  for (int b = 0; b < num_blocks; ++b) {
    summaries_[b] = SummaryAt(b, k[blocks_[b].parameters[0]], true);
  }
}

void PatchAgreementTerm::BlockCosts(const Eigen::VectorXd& k, std::vector<double>* costs) {
  const int num_blocks = static_cast<int>(blocks_.size());
  costs->resize(num_blocks);
#pragma omp parallel for schedule(dynamic, 64)
  for (int b = 0; b < num_blocks; ++b) {
    (*costs)[b] = SummaryAt(b, k[blocks_[b].parameters[0]], false).squared_norm;
  }
}

}  // namespace finecap
