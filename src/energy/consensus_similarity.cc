#include "energy/consensus_similarity.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "energy/surface_color_similarity.h"
#include "finecap/util/error.h"
#include "model/image_color.h"
#include "model/surface_projection.h"
#include "util/fast_exp.h"

namespace finecap {
namespace {

// A patch needs a centre and at least this many neighbours to have a shape worth comparing.
constexpr int kMinPatchNeighbours = 3;
// Table nodes per sigma_hat of displacement: a projected Gaussian moves by at most its own sigma
// over sigma_hat of k, over which its blurred colour changes smoothly; at half of that the cubic
// Hermite interpolation (exact slopes at the nodes) is far below the image noise. Three nodes
// per sigma gave the same surfaces (synth_skirt and the 5 cm folds within 0.0001 mm, the
// temple's held-out NCC within 0.0002) for 1.5 times the tables' time and memory.
constexpr double kNodesPerSigma = 2.0;

// Row of each surface Gaussian in a camera's pair list, -1 where the camera does not see it.
std::vector<int> RowsOf(const CameraPairs& pairs, int num_surface) {
  std::vector<int> rows(num_surface, -1);
  for (int row = 0; row < static_cast<int>(pairs.surface_ids.size()); ++row) {
    rows[pairs.surface_ids[row]] = row;
  }
  return rows;
}

// The colours q of a patch in one camera, normalised, z_m = (q_m - mean) / deviation with
// deviation = sqrt(variance + floor^2), the mean per channel and the variance per channel or, when
// `pooled`, over all three channels (one gain for the camera); and, when `dq` is given, dz/dk from
// dq/dk: dz_m/dk = (dq_m/dk - mean dq/dk - z_m <z, dq/dk>) / deviation, where <z, dq/dk> is the
// mean over the patch (and the channels, when pooled) of z_j dq_j/dk.
void Normalise(const std::vector<Eigen::Vector3d>& q, const std::vector<Eigen::Vector3d>* dq,
               double floor, bool pooled, std::vector<Eigen::Vector3d>* z,
               std::vector<Eigen::Vector3d>* dz) {
  const int n = static_cast<int>(q.size());
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& value : q) mean += value;
  mean /= n;
  Eigen::Array3d variance = Eigen::Array3d::Zero();
  for (const Eigen::Vector3d& value : q) variance += (value - mean).array().square();
  variance /= n;
  if (pooled) variance.setConstant(variance.mean());
  const Eigen::Array3d inverse_deviation = (variance + floor * floor).sqrt().inverse();
  z->resize(n);
  for (int m = 0; m < n; ++m) (*z)[m] = ((q[m] - mean).array() * inverse_deviation).matrix();
  if (dq == nullptr) return;
  Eigen::Array3d mean_derivative = Eigen::Array3d::Zero(), z_dot_dq = Eigen::Array3d::Zero();
  for (int j = 0; j < n; ++j) {
    mean_derivative += (*dq)[j].array() / n;
    z_dot_dq += (*z)[j].array() * (*dq)[j].array() / n;
  }
  if (pooled) z_dot_dq.setConstant(z_dot_dq.mean());
  dz->resize(n);
  for (int m = 0; m < n; ++m) {
    (*dz)[m] =
        (((*dq)[m].array() - mean_derivative - (*z)[m].array() * z_dot_dq) * inverse_deviation)
            .matrix();
  }
}

// Scales a block's residuals r (and their derivatives dr/dk, when given) so that their sum of
// squares becomes rho(|r|^2) = c2 log(1 + |r|^2 / c2), Cauchy's loss: a block that disagrees far
// more than c2 stops pulling its Gaussian harder, and the regulariser carries its neighbours'
// displacement into it. r' = alpha r with alpha = sqrt(rho(s) / s), s = |r|^2, and
// dr'/dk = alpha dr/dk + r (d alpha / ds) 2 <r, dr/dk>.
void Robustify(double c2, int num_residuals, double* residuals, double* jacobian) {
  if (c2 <= 0.0) return;
  double s = 0.0, ds = 0.0;
  for (int r = 0; r < num_residuals; ++r) {
    s += residuals[r] * residuals[r];
    if (jacobian != nullptr) ds += 2.0 * residuals[r] * jacobian[r];
  }
  const double u = s / c2;
  // Below u ~ 1e-6 the closed forms lose digits; their Taylor series are exact to O(u^2) there.
  double alpha, dalpha_ds;
  if (u < 1e-6) {
    alpha = 1.0 - 0.25 * u;
    dalpha_ds = -0.25 / c2;
  } else {
    const double rho = c2 * std::log1p(u);
    const double drho = 1.0 / (1.0 + u);
    alpha = std::sqrt(rho / s);
    dalpha_ds = (drho * s - rho) / (2.0 * alpha * s * s);
  }
  for (int r = 0; r < num_residuals; ++r) {
    if (jacobian != nullptr) jacobian[r] = alpha * jacobian[r] + residuals[r] * dalpha_ds * ds;
    residuals[r] *= alpha;
  }
}

}  // namespace

ConsensusSimilarity::ConsensusSimilarity(const SurfaceGaussians& surface,
                                         const std::vector<EnergyView>& views,
                                         const std::vector<std::vector<int>>& one_rings,
                                         OverlapForm form, double k_max, double reach_sigmas,
                                         const ConsensusOptions& options)
    : surface_(surface),
      views_(views),
      form_(form),
      reach_sigmas_(reach_sigmas),
      options_(options),
      scale_(1.0 / std::sqrt(static_cast<double>(std::max<size_t>(views.size(), 1)))) {
  options_.Check();
  Require(one_rings.size() == static_cast<size_t>(surface.size()), "consensus similarity",
          "one neighbour list per surface Gaussian expected");
  std::vector<std::vector<int>> rows_of(views.size());
  for (size_t c = 0; c < views.size(); ++c) rows_of[c] = RowsOf(views[c].pairs, surface.size());

  for (int s = 0; s < surface.size(); ++s) {
    if (static_cast<int>(one_rings[s].size()) < kMinPatchNeighbours) continue;
    std::vector<int> patch = {s};
    patch.insert(patch.end(), one_rings[s].begin(), one_rings[s].end());
    std::vector<int> cameras;
    std::vector<std::vector<int>> rows;
    for (size_t c = 0; c < views.size(); ++c) {
      std::vector<int> patch_rows;
      for (int j : patch) patch_rows.push_back(rows_of[c][j]);
      if (std::find(patch_rows.begin(), patch_rows.end(), -1) != patch_rows.end()) continue;
      cameras.push_back(static_cast<int>(c));
      rows.push_back(std::move(patch_rows));
    }
    if (static_cast<int>(cameras.size()) < options_.min_cameras) continue;
    camera_begin_.push_back(static_cast<int>(cameras_.size()));
    cameras_.insert(cameras_.end(), cameras.begin(), cameras.end());
    for (auto& patch_rows : rows) rows_.push_back(std::move(patch_rows));
    blocks_.push_back({{s}, 3 * static_cast<int>(cameras.size() * patch.size())});
  }
  camera_begin_.push_back(static_cast<int>(cameras_.size()));

  residual_begin_.assign(1, 0);
  for (const ResidualBlock& block : blocks_) {
    residual_begin_.push_back(residual_begin_.back() + block.num_residuals);
  }
  shape_ = Eigen::VectorXd::Zero(surface.size());
  BuildTables(k_max);
  weights_.resize(blocks_.size());
#pragma omp parallel for schedule(dynamic, 64)
  for (int b = 0; b < static_cast<int>(blocks_.size()); ++b) weights_[b] = PatchContrast(b);
}

int ConsensusSimilarity::NumTableNodes(double sigma_hat, double k_max) {
  return static_cast<int>(std::ceil(2.0 * k_max / (sigma_hat / kNodesPerSigma))) + 1;
}

void ConsensusSimilarity::BuildTables(double k_max) {
  num_nodes_ = NumTableNodes(surface_.sigma_hat, k_max);
  node_step_ = 2.0 * k_max / (num_nodes_ - 1);
  node_k0_ = -k_max;
  table_.resize(views_.size());
  for (size_t c = 0; c < views_.size(); ++c) {
    const int num_rows = static_cast<int>(views_[c].pairs.surface_ids.size());
    table_[c].resize(long(num_rows) * num_nodes_);
#pragma omp parallel
    {
      RowImageGaussians paired;
#pragma omp for schedule(dynamic, 16)
      for (int row = 0; row < num_rows; ++row) {
        TabulateRow(views_[c], row, &paired, &table_[c][long(row) * num_nodes_]);
      }
    }
  }
}

void ConsensusSimilarity::RowImageGaussians::Assign(const EnergyView& view, int row,
                                                    OverlapForm form) {
  const CameraPairs& pairs = view.pairs;
  const int n = pairs.begin[row + 1] - pairs.begin[row];
  for (std::vector<float>* values :
       {&x, &y, &variance, &scaled_variance, &color[0], &color[1], &color[2]}) {
    values->resize(n);
  }
  for (int i = 0; i < n; ++i) {
    const ImageGaussian& g = (*view.image)[pairs.image_ids[pairs.begin[row] + i]];
    x[i] = g.x;
    y[i] = g.y;
    variance[i] = g.sigma * g.sigma;
    scaled_variance[i] = static_cast<float>(ImageVarianceFactor(form)) * variance[i];
    for (int channel = 0; channel < 3; ++channel) color[channel][i] = g.color[channel];
  }
}

namespace {

// Over the image Gaussians of a row: the sums of their overlaps E with a projected surface
// Gaussian, of dE/dk, and of both times their colours (the terms of ColorAccumulator).
struct OverlapSums {
  float overlap = 0.0f, doverlap = 0.0f;
  float weighted[3] = {0.0f, 0.0f, 0.0f};
  float dweighted[3] = {0.0f, 0.0f, 0.0f};
};

// GaussianOverlap and its k-derivative for every image Gaussian of `row` within `reach_sigmas`
// combined standard deviations (as ImageColorAround counts them), summed. With what depends only
// on the projected Gaussian taken out of the loop, and in single precision (the tables hold single
// precision), so that the loop runs over several image Gaussians at a time: eight with AVX2, where
// the processor has it (chosen when the program loads; the build itself assumes only SSE2).
__attribute__((target_clones("avx2", "default"))) OverlapSums SumOverlaps(
    const ConsensusSimilarity::RowImageGaussians& row, const ProjectedGaussian& projected,
    double exponent_divisor, double reach_sigmas) {
  const int n = static_cast<int>(row.x.size());
  const float* x = row.x.data();
  const float* y = row.y.data();
  const float* variance = row.variance.data();
  const float* scaled_variance = row.scaled_variance.data();
  const float* red = row.color[0].data();
  const float* green = row.color[1].data();
  const float* blue = row.color[2].data();
  const float inverse_divisor = static_cast<float>(1.0 / exponent_divisor);
  const float reach2 = static_cast<float>(reach_sigmas * reach_sigmas);
  const float mean_x = static_cast<float>(projected.mean.x());
  const float mean_y = static_cast<float>(projected.mean.y());
  const float dmean_x = static_cast<float>(projected.dmean_dk.x());
  const float dmean_y = static_cast<float>(projected.dmean_dk.y());
  const float var_s = static_cast<float>(projected.sigma * projected.sigma);
  const float two_pi_var_s = static_cast<float>(2.0 * M_PI) * var_s;
  const float inverse_var_s = 1.0f / var_s;
  const float dvar_dk = static_cast<float>(2.0 * projected.sigma * projected.dsigma_dk);
  float overlap_sum = 0.0f, doverlap_sum = 0.0f;
  float red_sum = 0.0f, green_sum = 0.0f, blue_sum = 0.0f;
  float dred_sum = 0.0f, dgreen_sum = 0.0f, dblue_sum = 0.0f;
#pragma omp simd reduction(+ : overlap_sum, doverlap_sum, red_sum, green_sum, blue_sum, dred_sum, \
                               dgreen_sum, dblue_sum)
  for (int i = 0; i < n; ++i) {
    const float dx = x[i] - mean_x, dy = y[i] - mean_y;
    const float d2 = dx * dx + dy * dy;
    const float in_reach = d2 <= reach2 * (var_s + variance[i]) ? 1.0f : 0.0f;
    const float inverse_sum = 1.0f / (var_s + scaled_variance[i]);
    const float spread = d2 * inverse_divisor * inverse_sum;
    const float overlap =
        in_reach * two_pi_var_s * variance[i] * inverse_sum * internal::FastExpNonPositive(-spread);
    const float dlog_dk = (inverse_var_s - inverse_sum + spread * inverse_sum) * dvar_dk +
                          2.0f * (dx * dmean_x + dy * dmean_y) * inverse_divisor * inverse_sum;
    const float doverlap = overlap * dlog_dk;
    overlap_sum += overlap;
    doverlap_sum += doverlap;
    red_sum += overlap * red[i];
    green_sum += overlap * green[i];
    blue_sum += overlap * blue[i];
    dred_sum += doverlap * red[i];
    dgreen_sum += doverlap * green[i];
    dblue_sum += doverlap * blue[i];
  }
  return {
      overlap_sum, doverlap_sum, {red_sum, green_sum, blue_sum}, {dred_sum, dgreen_sum, dblue_sum}};
}

}  // namespace

void ConsensusSimilarity::TabulateRow(const EnergyView& view, int row, RowImageGaussians* paired,
                                      TableNode* nodes) const {
  const int s = view.pairs.surface_ids[row];
  paired->Assign(view, row, form_);
  const Eigen::Vector3d fallback = surface_.colors[s].cast<double>();
  for (int node = 0; node < num_nodes_; ++node) {
    const ProjectedGaussian projected =
        ProjectSurfaceGaussian(view.camera, surface_.base.col(s), surface_.normals.col(s),
                               node_k0_ + node * node_step_, surface_.sigma_hat);
    const OverlapSums sums = SumOverlaps(*paired, projected, ExponentDivisor(form_), reach_sigmas_);
    internal::ColorAccumulator accumulator(fallback);
    accumulator.AddSums(sums.overlap, sums.doverlap,
                        Eigen::Vector3d(sums.weighted[0], sums.weighted[1], sums.weighted[2]),
                        Eigen::Vector3d(sums.dweighted[0], sums.dweighted[1], sums.dweighted[2]));
    nodes[node].color = accumulator.Mean().cast<float>();
    nodes[node].slope = (node_step_ * accumulator.MeanDerivative()).cast<float>();
  }
}

void ConsensusSimilarity::PatchColors(int a, double k, std::vector<Eigen::Vector3d>* colors,
                                      std::vector<Eigen::Vector3d>* derivatives,
                                      const RowColors* row_colors) const {
  const int c = cameras_[a];
  const std::vector<int>& rows = rows_[a];
  const int n = static_cast<int>(rows.size());
  colors->resize(n);
  if (row_colors != nullptr) {
    for (int m = 0; m < n; ++m) (*colors)[m] = (*row_colors)[c][rows[m]];
    return;
  }
  if (derivatives != nullptr) derivatives->resize(n);
  const EnergyView& view = views_[c];
  const double centre_shape = shape_[view.pairs.surface_ids[rows[0]]];
  for (int m = 0; m < n; ++m) {
    const double member_k = k + shape_[view.pairs.surface_ids[rows[m]]] - centre_shape;
    (*colors)[m] = Interpolate(c, rows[m], member_k, derivatives ? &(*derivatives)[m] : nullptr);
  }
}

Eigen::Vector3d ConsensusSimilarity::Interpolate(int c, int row, double k,
                                                 Eigen::Vector3d* derivative) const {
  // Cubic Hermite basis on the node interval holding k; beyond the table the colour stays at
  // its end value.
  const double x = std::clamp((k - node_k0_) / node_step_, 0.0, num_nodes_ - 1.0);
  const int g = std::min(static_cast<int>(x), num_nodes_ - 2);
  const double t = x - g, t2 = t * t, t3 = t2 * t;
  const TableNode* node = &table_[c][long(row) * num_nodes_ + g];
  const Eigen::Vector3d p0 = node[0].color.cast<double>();
  const Eigen::Vector3d p1 = node[1].color.cast<double>();
  const Eigen::Vector3d m0 = node[0].slope.cast<double>();
  const Eigen::Vector3d m1 = node[1].slope.cast<double>();
  if (derivative != nullptr) {
    const bool inside = k > node_k0_ && k < node_k0_ + (num_nodes_ - 1) * node_step_;
    derivative->setZero();
    if (inside) {
      *derivative = ((6 * t2 - 6 * t) * p0 + (3 * t2 - 4 * t + 1) * m0 + (-6 * t2 + 6 * t) * p1 +
                     (3 * t2 - 2 * t) * m1) /
                    node_step_;
    }
  }
  return (2 * t3 - 3 * t2 + 1) * p0 + (t3 - 2 * t2 + t) * m0 + (-2 * t3 + 3 * t2) * p1 +
         (t3 - t2) * m1;
}

void ConsensusSimilarity::SetPatchShape(const Eigen::VectorXd& shape) {
  Require(shape.size() == surface_.size(), "consensus similarity",
          "one patch shape entry per surface Gaussian expected");
  shape_ = shape;
}

Eigen::Vector3d ConsensusSimilarity::PatchContrast(int b) const {
  Eigen::Vector3d variance = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> colors;
  for (int a = camera_begin_[b]; a < camera_begin_[b + 1]; ++a) {
    PatchColors(a, 0.0, &colors, nullptr);
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& color : colors) mean += color / colors.size();
    for (const Eigen::Vector3d& color : colors)
      variance += (color - mean).cwiseAbs2() / colors.size();
  }
  return (variance / (camera_begin_[b + 1] - camera_begin_[b])).cwiseSqrt();
}

void ConsensusSimilarity::BlockAt(int b, double k, double* residuals, double* jacobian,
                                  const RowColors* row_colors) const {
  const int num_cameras = camera_begin_[b + 1] - camera_begin_[b];
  // Each thread keeps its buffers from block to block: a frame's sweep and solve call this ~10^6
  // times, and allocating them each time cost ~2 % of the frame's work.
  thread_local std::vector<std::vector<Eigen::Vector3d>> z, dz;
  thread_local std::vector<Eigen::Vector3d> q, dq;
  z.resize(num_cameras);
  dz.resize(num_cameras);
  for (int a = 0; a < num_cameras; ++a) {
    PatchColors(camera_begin_[b] + a, k, &q, jacobian != nullptr ? &dq : nullptr, row_colors);
    Normalise(q, jacobian != nullptr ? &dq : nullptr, options_.contrast_floor,
              !options_.gain_per_channel, &z[a], &dz[a]);
  }
  const int n = static_cast<int>(z[0].size());
  const Eigen::Vector3d weight = scale_ * weights_[b];
  for (int m = 0; m < n; ++m) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero(), mean_derivative = Eigen::Vector3d::Zero();
    for (int a = 0; a < num_cameras; ++a) {
      mean += z[a][m] / num_cameras;
      if (jacobian != nullptr) mean_derivative += dz[a][m] / num_cameras;
    }
    for (int a = 0; a < num_cameras; ++a) {
      const Eigen::Vector3d r = weight.cwiseProduct(z[a][m] - mean);
      std::copy_n(r.data(), 3, residuals + (a * n + m) * 3);
      if (jacobian == nullptr) continue;
      const Eigen::Vector3d d = weight.cwiseProduct(dz[a][m] - mean_derivative);
      std::copy_n(d.data(), 3, jacobian + (a * n + m) * 3);
    }
  }
  if (options_.robust_fraction > 0.0) {
    // The level of disagreement of unrelated patches: each normalised channel has unit
    // variance, so sum_m |z_m - mean_c z_m|^2 is about 3 n (n_c - 1) for them.
    const double unrelated =
        3.0 * n * (num_cameras - 1) * (scale_ * weights_[b]).squaredNorm() / 3.0;
    Robustify(options_.robust_fraction * unrelated, blocks_[b].num_residuals, residuals, jacobian);
  }
}

double ConsensusSimilarity::Evaluate(const Eigen::VectorXd& k, Eigen::VectorXd* gradient) const {
  if (gradient != nullptr) *gradient = Eigen::VectorXd::Zero(k.size());
  const int num_blocks = static_cast<int>(blocks_.size());
  double sum_of_squares = 0.0;
#pragma omp parallel reduction(+ : sum_of_squares)
  {
    std::vector<double> residuals, jacobian;
#pragma omp for schedule(dynamic, 64)
    for (int b = 0; b < num_blocks; ++b) {
      const int s = blocks_[b].parameters[0];
      residuals.resize(blocks_[b].num_residuals);
      jacobian.resize(residuals.size());
      BlockAt(b, k[s], residuals.data(), gradient != nullptr ? jacobian.data() : nullptr);
      double dcost = 0.0;
      for (size_t r = 0; r < residuals.size(); ++r) {
        sum_of_squares += residuals[r] * residuals[r];
        if (gradient != nullptr) dcost += residuals[r] * jacobian[r];
      }
      // Each block owns one parameter: no two threads write the same entry.
      if (gradient != nullptr) (*gradient)[s] = -dcost;
    }
  }
  return -0.5 * sum_of_squares;
}

void ConsensusSimilarity::PrepareResiduals(const Eigen::VectorXd& k, bool with_jacobians) {
  residuals_.resize(residual_begin_.back());
  jacobians_.resize(with_jacobians ? residual_begin_.back() : 0);
  const int num_blocks = static_cast<int>(blocks_.size());
#pragma omp parallel for schedule(dynamic, 64)
  for (int b = 0; b < num_blocks; ++b) {
    BlockAt(b, k[blocks_[b].parameters[0]], &residuals_[residual_begin_[b]],
            with_jacobians ? &jacobians_[residual_begin_[b]] : nullptr);
  }
}

void ConsensusSimilarity::PrepareBlockSummaries(const Eigen::VectorXd& k) {
  const int num_blocks = static_cast<int>(blocks_.size());
  summaries_.resize(num_blocks);
#pragma omp parallel
  {
    std::vector<double> residuals, jacobian;
#pragma omp for schedule(dynamic, 64)
    for (int b = 0; b < num_blocks; ++b) {
      residuals.resize(blocks_[b].num_residuals);
      jacobian.resize(residuals.size());
      BlockAt(b, k[blocks_[b].parameters[0]], residuals.data(), jacobian.data());
      summaries_[b] = Summarise(residuals.data(), jacobian.data(), blocks_[b].num_residuals);
    }
  }
}

void ConsensusSimilarity::BlockCosts(const Eigen::VectorXd& k, std::vector<double>* costs) {
  const bool uniform = k.size() > 0 && (k.array() == k[0]).all() && shape_.isZero(0.0);
  if (!uniform) {
    SimilarityTerm::BlockCosts(k, costs);
    return;
  }
  RowColors row_colors(views_.size());
  std::vector<std::pair<int, int>> rows;  // (camera, row) of every row of every camera.
  for (size_t c = 0; c < views_.size(); ++c) {
    const int num_rows = static_cast<int>(views_[c].pairs.surface_ids.size());
    row_colors[c].resize(num_rows);
    for (int row = 0; row < num_rows; ++row) rows.emplace_back(static_cast<int>(c), row);
  }
  const int num_rows = static_cast<int>(rows.size());
  const int num_blocks = static_cast<int>(blocks_.size());
  costs->resize(num_blocks);
  // One parallel region for both loops: on a busy machine each region's start and barrier can
  // wait a time slice for a thread, and the sweep calls this for every sample.
#pragma omp parallel
  {
#pragma omp for schedule(static)
    for (int i = 0; i < num_rows; ++i) {
      const auto [c, row] = rows[i];
      row_colors[c][row] = Interpolate(c, row, k[0], nullptr);
    }
    std::vector<double> residuals;
#pragma omp for schedule(dynamic, 64)
    for (int b = 0; b < num_blocks; ++b) {
      residuals.resize(blocks_[b].num_residuals);
      BlockAt(b, k[0], residuals.data(), nullptr, &row_colors);
      double cost = 0.0;
      for (double r : residuals) cost += r * r;
      (*costs)[b] = cost;
    }
  }
}

void ConsensusSimilarity::BlockResiduals(int block, double* residuals, double* jacobian) const {
  const long begin = residual_begin_[block];
  const int num_residuals = blocks_[block].num_residuals;
  std::copy_n(&residuals_[begin], num_residuals, residuals);
  if (jacobian != nullptr) std::copy_n(&jacobians_[begin], num_residuals, jacobian);
}

}  // namespace finecap
