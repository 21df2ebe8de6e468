#include "energy/terms/consensus/surface_consensus_similarity.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/SparseCore>

#include "energy/terms/consensus/patch_agreement.h"
#include "finecap/util/error.h"

namespace finecap {
namespace {

using SampleWeights = Eigen::SparseMatrix<double, Eigen::RowMajor>;

// A sample lies on a triangle: its blend has at most three corners.
constexpr int kMaxCorners = 3;

// The reduced rows of a block (surface_consensus_similarity.h): `rows` (p + 1) and their
// Jacobian `jacobian` ((p + 1) x p, row-major) from its cost s, gradient g and Gauss-Newton
// matrix h = L L^T: the rows L^T with residuals L^-1 g. h is only semi-definite where a corner's
// weights are all but zero, so the factor is of h with its diagonal raised by a share of its
// largest entry too small to change a step (kRelativeRidge), and g lies in h's range (g = J^T r).
void ReducedRows(double s, const Eigen::VectorXd& g, Eigen::MatrixXd* h, double* rows,
                 double* jacobian) {
  constexpr double kRelativeRidge = 1e-12;
  const int p = static_cast<int>(g.size());
  const double largest = h->diagonal().maxCoeff();
  if (!(largest > 0.0)) {  // No derivative at all: the cost alone.
    std::fill_n(rows, p, 0.0);
    rows[p] = std::sqrt(s);
    std::fill_n(jacobian, (p + 1) * p, 0.0);
    return;
  }
  h->diagonal().array() += kRelativeRidge * largest;
  const Eigen::LLT<Eigen::MatrixXd, Eigen::Lower> factor(*h);
  Eigen::Map<Eigen::VectorXd> reducible(rows, p);
  reducible = factor.matrixL().solve(g);
  for (int i = 0; i < p; ++i) {
    for (int q = 0; q < p; ++q) jacobian[i * p + q] = q >= i ? factor.matrixLLT()(q, i) : 0.0;
  }
  // What of r no step can reduce; rounding may make the difference a hair negative.
  rows[p] = std::sqrt(std::max(0.0, s - reducible.squaredNorm()));
  std::fill_n(jacobian + p * p, p, 0.0);
}

}  // namespace

SurfaceConsensusSimilarity::SurfaceConsensusSimilarity(const PixelConsensusSimilarity& patches,
                                                       const SurfaceSamples& samples,
                                                       const ConsensusOptions& options)
    : patches_(patches), samples_(samples), options_(options) {
  options_.Check();
  row_begin_.assign(1, 0);
  jacobian_begin_.assign(1, 0);
  for (int b = 0; b < static_cast<int>(patches.residual_blocks().size()); ++b) {
    // The block's unknowns: every corner a sample of its patch is blended from.
    std::vector<int> unknowns;
    const int* members = patches.Members(b);
    for (int j = 0; j < patches.PatchSize(b); ++j) {
      Require(samples.weights.row(members[j]).nonZeros() <= kMaxCorners,
              "surface consensus similarity", "a sample is blended from at most 3 corners");
      for (SampleWeights::InnerIterator it(samples.weights, members[j]); it; ++it) {
        unknowns.push_back(static_cast<int>(it.col()));
      }
    }
    std::sort(unknowns.begin(), unknowns.end());
    unknowns.erase(std::unique(unknowns.begin(), unknowns.end()), unknowns.end());
    const int p = static_cast<int>(unknowns.size());
    blocks_.push_back({std::move(unknowns), p + 1});
    row_begin_.push_back(row_begin_.back() + p + 1);
    jacobian_begin_.push_back(jacobian_begin_.back() + static_cast<long>(p + 1) * p);
  }
  IndexContributions(samples.weights.cols());
}

void SurfaceConsensusSimilarity::IndexContributions(int num_unknowns) {
  parameter_begin_.assign(1, 0);
  std::vector<int> count(num_unknowns, 0);
  for (const ResidualBlock& block : blocks_) {
    parameter_begin_.push_back(parameter_begin_.back() +
                               static_cast<long>(block.parameters.size()));
    for (int s : block.parameters) ++count[s];
  }
  contribution_begin_.assign(1, 0);
  for (int s = 0; s < num_unknowns; ++s) {
    contribution_begin_.push_back(contribution_begin_.back() + count[s]);
  }
  contributions_.resize(contribution_begin_.back());
  std::vector<long> next(contribution_begin_.begin(), contribution_begin_.end() - 1);
  for (size_t b = 0; b < blocks_.size(); ++b) {
    const std::vector<int>& unknowns = blocks_[b].parameters;
    for (size_t i = 0; i < unknowns.size(); ++i) {
      contributions_[next[unknowns[i]]++] = parameter_begin_[b] + static_cast<long>(i);
    }
  }
}

Eigen::VectorXd SurfaceConsensusSimilarity::Gather(const std::vector<double>& per_block_entry,
                                                   int num_unknowns) const {
  Eigen::VectorXd sums = Eigen::VectorXd::Zero(num_unknowns);
#pragma omp parallel for schedule(static)
  for (int s = 0; s < num_unknowns; ++s) {
    for (long c = contribution_begin_[s]; c < contribution_begin_[s + 1]; ++c) {
      sums[s] += per_block_entry[contributions_[c]];
    }
  }
  return sums;
}

int SurfaceConsensusSimilarity::CornersOf(int block, int sample, int* local,
                                          double* weights) const {
  const std::vector<int>& unknowns = blocks_[block].parameters;
  int corners = 0;
  for (SampleWeights::InnerIterator it(samples_.weights, sample); it; ++it, ++corners) {
    local[corners] = static_cast<int>(std::lower_bound(unknowns.begin(), unknowns.end(), it.col()) -
                                      unknowns.begin());
    weights[corners] = it.value();
  }
  return corners;
}

void SurfaceConsensusSimilarity::ReadNormalised(int block, const Eigen::VectorXd& k,
                                                std::vector<double>* z,
                                                std::vector<double>* derivatives,
                                                std::vector<double>* inverse_deviations) const {
  const int n = patches_.PatchSize(block), num_cameras = patches_.NumCameras(block);
  const int* members = patches_.Members(block);
  thread_local std::vector<double> member_k;
  member_k.assign(n, 0.0);
  for (int j = 0; j < n; ++j) {
    for (SampleWeights::InnerIterator it(samples_.weights, members[j]); it; ++it) {
      member_k[j] += it.value() * k[it.col()];
    }
  }
  const int stride = 3 * n;
  z->resize(static_cast<size_t>(stride) * num_cameras);
  if (derivatives != nullptr) derivatives->resize(z->size());
  patches_.ReadPatch(block, member_k.data(), z->data(),
                     derivatives != nullptr ? derivatives->data() : nullptr);
  inverse_deviations->resize(3 * num_cameras);
  for (int a = 0; a < num_cameras; ++a) {
    internal::NormaliseColors(n, options_.contrast_floor, !options_.gain_per_channel,
                              &(*z)[stride * a], &(*inverse_deviations)[3 * a]);
  }
}

void SurfaceConsensusSimilarity::PlainResidualsOfBlock(int block, const Eigen::VectorXd& k,
                                                       Eigen::VectorXd* residuals,
                                                       Eigen::MatrixXd* jacobian) const {
  const int n = patches_.PatchSize(block), num_cameras = patches_.NumCameras(block);
  const int* members = patches_.Members(block);
  const std::vector<int>& unknowns = blocks_[block].parameters;
  const int m = 3 * n * num_cameras, stride = 3 * n;
  thread_local std::vector<double> derivatives, z, inverse_deviations;
  ReadNormalised(block, k, &z, jacobian != nullptr ? &derivatives : nullptr, &inverse_deviations);
  const bool pooled = !options_.gain_per_channel;
  const Eigen::Vector3d weight = patches_.ResidualWeight(block);
  *residuals = Eigen::Map<const Eigen::VectorXd>(z.data(), m);
  internal::AgainstCameraMean(n, num_cameras, weight, residuals->data());
  if (jacobian == nullptr) return;
  // A colour moves with its own sample's displacement, which corner v moves by the sample's
  // weight on v; each corner's column then goes through the normalisation as one direction of k.
  const int p = static_cast<int>(unknowns.size());
  jacobian->setZero(m, p);
  int local[kMaxCorners];
  double weights[kMaxCorners];
  for (int j = 0; j < n; ++j) {
    const int corners = CornersOf(block, members[j], local, weights);
    for (int q = 0; q < corners; ++q) {
      for (int a = 0; a < num_cameras; ++a) {
        for (int channel = 0; channel < 3; ++channel) {
          const int r = stride * a + 3 * j + channel;
          (*jacobian)(r, local[q]) = weights[q] * derivatives[r];
        }
      }
    }
  }
  for (int i = 0; i < p; ++i) {
    double* column = jacobian->col(i).data();
    for (int a = 0; a < num_cameras; ++a) {
      internal::NormaliseDerivative(n, pooled, &z[stride * a], &inverse_deviations[3 * a],
                                    column + stride * a);
    }
    internal::AgainstCameraMean(n, num_cameras, weight, column);
  }
}

void SurfaceConsensusSimilarity::ResidualsOfBlock(int block, const Eigen::VectorXd& k,
                                                  Eigen::VectorXd* residuals,
                                                  Eigen::MatrixXd* jacobian) const {
  PlainResidualsOfBlock(block, k, residuals, jacobian);
  const double c2 = patches_.LossScale(block);
  const int m = static_cast<int>(residuals->size());
  const double root_weight = std::sqrt(options_.surface_weight);
  if (jacobian != nullptr) {
    for (int i = 0; i < jacobian->cols(); ++i) {
      Eigen::VectorXd plain = *residuals;  // Robustify scales the residuals it is given.
      internal::Robustify(c2, m, plain.data(), jacobian->col(i).data());
    }
    *jacobian *= root_weight;
  }
  internal::Robustify(c2, m, residuals->data(), nullptr);
  *residuals *= root_weight;
}

double SurfaceConsensusSimilarity::PlainModelOfBlock(int block, const Eigen::VectorXd& k,
                                                     Eigen::VectorXd* gradient,
                                                     Eigen::MatrixXd* curvature) const {
  // Notation of the derivation (docs/method.md, "The refined mesh itself"): camera a of the
  // block's C, member m of its n, channel c; z the normalised colours, s_ac their inverse
  // deviations, d the colours' derivatives in their own sample's displacement, W_mi the weight of
  // member m on unknown i, w_c the residuals' weight, y = z - (the cameras' mean of z).
  const int n = patches_.PatchSize(block), num_cameras = patches_.NumCameras(block);
  const int* members = patches_.Members(block);
  const std::vector<int>& unknowns = blocks_[block].parameters;
  const int p = static_cast<int>(unknowns.size()), channels = 3 * num_cameras;
  const int stride = 3 * n;
  thread_local std::vector<double> z, d, inverse_deviations, mean_z, per_unknown, gram;
  ReadNormalised(block, k, &z, &d, &inverse_deviations);
  const bool pooled = !options_.gain_per_channel;
  const Eigen::Vector3d weight = patches_.ResidualWeight(block);
  const Eigen::Vector3d w2 = weight.cwiseAbs2();
  const auto at = [&](int a, int j, int c) { return stride * a + 3 * j + c; };
  const auto s_of = [&](int a, int c) { return inverse_deviations[3 * a + c]; };

  // The cameras' mean of z, the cost, and per camera and channel the sum of z y.
  mean_z.assign(stride, 0.0);
  for (int a = 0; a < num_cameras; ++a) {
    for (int t = 0; t < stride; ++t) mean_z[t] += z[stride * a + t];
  }
  for (double& value : mean_z) value /= num_cameras;
  double squared_norm = 0.0;
  Eigen::VectorXd zy = Eigen::VectorXd::Zero(channels);
  for (int a = 0; a < num_cameras; ++a) {
    for (int j = 0; j < n; ++j) {
      for (int c = 0; c < 3; ++c) {
        const double y = z[at(a, j, c)] - mean_z[3 * j + c];
        squared_norm += w2[c] * y * y;
        zy[3 * a + c] += z[at(a, j, c)] * y;
      }
    }
  }
  // Gram of the cameras' z per channel: gram[(a * C + b) * 3 + c] = sum_m z_amc z_bmc.
  gram.assign(static_cast<size_t>(num_cameras) * num_cameras * 3, 0.0);
  for (int a = 0; a < num_cameras; ++a) {
    for (int b = a; b < num_cameras; ++b) {
      for (int c = 0; c < 3; ++c) {
        double sum = 0.0;
        for (int j = 0; j < n; ++j) sum += z[at(a, j, c)] * z[at(b, j, c)];
        gram[(a * num_cameras + b) * 3 + c] = gram[(b * num_cameras + a) * 3 + c] = sum;
      }
    }
  }

  // Per unknown i, over its members: mu_iac = sum W d / n, rho_iac = sum W z d and
  // sz_ibc = sum W E_mc z_bmc (E_mc = sum_a s_ac d_amc); the sparse parts of g and J^T J.
  // per_unknown holds, for unknown i, mu, rho and sz of 3 C entries each.
  per_unknown.assign(static_cast<size_t>(p) * 3 * channels, 0.0);
  const auto mu = [&](int i) { return &per_unknown[(3 * i) * channels]; };
  const auto rho = [&](int i) { return &per_unknown[(3 * i + 1) * channels]; };
  const auto sz = [&](int i) { return &per_unknown[(3 * i + 2) * channels]; };
  gradient->setZero(p);
  Eigen::MatrixXd own = Eigen::MatrixXd::Zero(p, p), across = Eigen::MatrixXd::Zero(p, p);
  int local[kMaxCorners];
  double weights[kMaxCorners];
  double e[3];
  for (int j = 0; j < n; ++j) {
    const int corners = CornersOf(block, members[j], local, weights);
    double own_scale = 0.0, gradient_scale = 0.0;
    for (int c = 0; c < 3; ++c) e[c] = 0.0;
    for (int a = 0; a < num_cameras; ++a) {
      for (int c = 0; c < 3; ++c) {
        const double sd = s_of(a, c) * d[at(a, j, c)];
        e[c] += sd;
        own_scale += w2[c] * sd * sd;
        gradient_scale += w2[c] * sd * (z[at(a, j, c)] - mean_z[3 * j + c]);
      }
    }
    const double across_scale = w2[0] * e[0] * e[0] + w2[1] * e[1] * e[1] + w2[2] * e[2] * e[2];
    for (int q = 0; q < corners; ++q) {
      const int i = local[q];
      const double wi = weights[q];
      (*gradient)[i] += wi * gradient_scale;
      for (int r = 0; r < corners; ++r) {
        own(i, local[r]) += wi * weights[r] * own_scale;
        across(i, local[r]) += wi * weights[r] * across_scale;
      }
      double* mu_i = mu(i);
      double* rho_i = rho(i);
      double* sz_i = sz(i);
      for (int a = 0; a < num_cameras; ++a) {
        for (int c = 0; c < 3; ++c) {
          const double wd = wi * d[at(a, j, c)];
          mu_i[3 * a + c] += wd;
          rho_i[3 * a + c] += wd * z[at(a, j, c)];
          sz_i[3 * a + c] += wi * e[c] * z[at(a, j, c)];
        }
      }
    }
  }
  // u_iac = s mu_iac and v_iac = s beta_iac, beta the normalisation's mean of z dq (per channel,
  // or over the three when the gain is pooled); u_hat_ic = sum_a u_iac.
  Eigen::MatrixXd u(p, channels), v(p, channels), u_hat(p, 3);
  for (int i = 0; i < p; ++i) {
    for (int a = 0; a < num_cameras; ++a) {
      const double pooled_beta = (rho(i)[3 * a] + rho(i)[3 * a + 1] + rho(i)[3 * a + 2]) / (3 * n);
      for (int c = 0; c < 3; ++c) {
        const double beta = pooled ? pooled_beta : rho(i)[3 * a + c] / n;
        u(i, 3 * a + c) = s_of(a, c) * mu(i)[3 * a + c] / n;
        v(i, 3 * a + c) = s_of(a, c) * beta;
      }
    }
    for (int c = 0; c < 3; ++c) {
      u_hat(i, c) = 0.0;
      for (int a = 0; a < num_cameras; ++a) u_hat(i, c) += u(i, 3 * a + c);
    }
  }
  Eigen::VectorXd w2_channels(channels), own_gram(channels);
  for (int a = 0; a < num_cameras; ++a) {
    for (int c = 0; c < 3; ++c) {
      w2_channels[3 * a + c] = w2[c];
      own_gram[3 * a + c] = gram[(a * num_cameras + a) * 3 + c];
    }
  }
  Eigen::MatrixXd s_rho(p, channels), w2_sz(p, channels);
  for (int i = 0; i < p; ++i) {
    for (int a = 0; a < num_cameras; ++a) {
      for (int c = 0; c < 3; ++c) {
        s_rho(i, 3 * a + c) = w2[c] * s_of(a, c) * rho(i)[3 * a + c];
        w2_sz(i, 3 * a + c) = w2[c] * sz(i)[3 * a + c];
      }
    }
  }
  // g = sum_m W R_m - sum_ac w^2 v zy.
  *gradient -= v * w2_channels.cwiseProduct(zy);
  // J^T J = A - B / C (the derivation's terms, in its order).
  const Eigen::MatrixXd v_w2 = v * w2_channels.asDiagonal();
  const Eigen::MatrixXd u_w2 = u * w2_channels.asDiagonal();
  Eigen::MatrixXd a_part = own - n * u_w2 * u.transpose() - v * s_rho.transpose() -
                           s_rho * v.transpose() + v_w2 * own_gram.asDiagonal() * v.transpose();
  Eigen::MatrixXd b_part = across - n * u_hat * w2.asDiagonal() * u_hat.transpose() -
                           v * w2_sz.transpose() - w2_sz * v.transpose();
  for (int c = 0; c < 3; ++c) {
    Eigen::MatrixXd channel_gram(num_cameras, num_cameras);
    Eigen::MatrixXd v_c(p, num_cameras);
    for (int a = 0; a < num_cameras; ++a) {
      v_c.col(a) = v.col(3 * a + c);
      for (int b = 0; b < num_cameras; ++b) {
        channel_gram(a, b) = gram[(a * num_cameras + b) * 3 + c];
      }
    }
    b_part += w2[c] * v_c * channel_gram * v_c.transpose();
  }
  *curvature = a_part - b_part / num_cameras;
  return squared_norm;
}

double SurfaceConsensusSimilarity::BlockModel(int block, const Eigen::VectorXd& k,
                                              Eigen::VectorXd* gradient,
                                              Eigen::MatrixXd* curvature) const {
  const double c2 = patches_.LossScale(block), weight = options_.surface_weight;
  if (gradient == nullptr) {
    thread_local Eigen::VectorXd residuals;
    PlainResidualsOfBlock(block, k, &residuals, nullptr);
    BlockSummary plain;
    plain.squared_norm = residuals.squaredNorm();
    return weight * internal::Robustify(c2, plain, false).squared_norm;
  }
  double squared_norm = PlainModelOfBlock(block, k, gradient, curvature);
  internal::Robustify(c2, &squared_norm, gradient, curvature);
  *gradient *= weight;
  *curvature *= weight;
  return weight * squared_norm;
}

double SurfaceConsensusSimilarity::Evaluate(const Eigen::VectorXd& k,
                                            Eigen::VectorXd* gradient) const {
  const int num_blocks = static_cast<int>(blocks_.size());
  std::vector<double> costs(num_blocks), entries(gradient != nullptr ? parameter_begin_.back() : 0);
#pragma omp parallel
  {
    Eigen::VectorXd block_gradient;
    Eigen::MatrixXd block_curvature;
#pragma omp for schedule(dynamic, 64)
    for (int b = 0; b < num_blocks; ++b) {
      if (gradient == nullptr) {
        costs[b] = BlockModel(b, k, nullptr, nullptr);
        continue;
      }
      costs[b] = BlockModel(b, k, &block_gradient, &block_curvature);
      std::copy_n(block_gradient.data(), block_gradient.size(), &entries[parameter_begin_[b]]);
    }
  }
  if (gradient != nullptr) *gradient = -Gather(entries, static_cast<int>(k.size()));
  double sum_of_squares = 0.0;
  for (double cost : costs) sum_of_squares += cost;
  return -0.5 * sum_of_squares;
}

void SurfaceConsensusSimilarity::PrepareResiduals(const Eigen::VectorXd& k, bool with_jacobians) {
  rows_.resize(row_begin_.back());
  row_jacobians_.resize(with_jacobians ? jacobian_begin_.back() : 0);
  const int num_blocks = static_cast<int>(blocks_.size());
#pragma omp parallel
  {
    Eigen::VectorXd gradient;
    Eigen::MatrixXd curvature;
#pragma omp for schedule(dynamic, 64)
    for (int b = 0; b < num_blocks; ++b) {
      double* rows = &rows_[row_begin_[b]];
      if (!with_jacobians) {
        // A cost alone: any rows with its sum of squares.
        rows[0] = std::sqrt(BlockModel(b, k, nullptr, nullptr));
        std::fill_n(rows + 1, blocks_[b].num_residuals - 1, 0.0);
        continue;
      }
      const double squared_norm = BlockModel(b, k, &gradient, &curvature);
      ReducedRows(squared_norm, gradient, &curvature, rows, &row_jacobians_[jacobian_begin_[b]]);
    }
  }
}

void SurfaceConsensusSimilarity::BlockResiduals(int block, double* residuals,
                                                double* jacobian) const {
  const int num_rows = blocks_[block].num_residuals;
  std::copy_n(&rows_[row_begin_[block]], num_rows, residuals);
  if (jacobian != nullptr) {
    std::copy_n(&row_jacobians_[jacobian_begin_[block]],
                jacobian_begin_[block + 1] - jacobian_begin_[block], jacobian);
  }
}

void SurfaceConsensusSimilarity::BlockCosts(const Eigen::VectorXd& k, std::vector<double>* costs) {
  const int num_blocks = static_cast<int>(blocks_.size());
  costs->resize(num_blocks);
#pragma omp parallel for schedule(dynamic, 64)
  for (int b = 0; b < num_blocks; ++b) (*costs)[b] = BlockModel(b, k, nullptr, nullptr);
}

Eigen::VectorXd SurfaceConsensusSimilarity::GaussNewtonDiagonal(const Eigen::VectorXd& k) {
  const int num_blocks = static_cast<int>(blocks_.size());
  std::vector<double> entries(parameter_begin_.back());
#pragma omp parallel
  {
    Eigen::VectorXd gradient;
    Eigen::MatrixXd curvature;
#pragma omp for schedule(dynamic, 64)
    for (int b = 0; b < num_blocks; ++b) {
      BlockModel(b, k, &gradient, &curvature);
      for (Eigen::Index i = 0; i < curvature.rows(); ++i) {
        entries[parameter_begin_[b] + i] = curvature(i, i);
      }
    }
  }
  return Gather(entries, static_cast<int>(k.size()));
}

}  // namespace finecap
