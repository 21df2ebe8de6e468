#include "energy/terms/consensus/consensus_similarity.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "energy/terms/consensus/patch_agreement.h"
#include "energy/terms/surface_color/surface_color_similarity.h"
#include "finecap/util/error.h"
#include "model/image_color.h"
#include "model/surface_projection.h"
#include "util/fast_exp.h"

namespace finecap {
namespace {

using internal::Robustify;

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

// The values of one quantity at kLanes displacements side by side (the plane sweep's samples),
// so that the loops over them run over several at a time. Each lane gets the same operations in
// the same order as a single displacement would, so the same bits: Eigen's packets round every
// operation as the scalar one does, and the build contracts no multiply-add (SSE2).
template <int kLanes>
using Lanes = Eigen::Array<double, kLanes, 1>;

template <int kLanes>
Eigen::Map<Lanes<kLanes>> LanesAt(double* values) {
  return Eigen::Map<Lanes<kLanes>>(values);
}

template <int kLanes>
Eigen::Map<const Lanes<kLanes>> LanesAt(const double* values) {
  return Eigen::Map<const Lanes<kLanes>>(values);
}

// Normalise without derivatives, of one patch in one camera at kLanes displacements at once,
// reading its members' colours from `lane_colors` (table row `rows[m]` of member m, its channel
// c at lane l in lane_colors[(3 rows[m] + c) kLanes + l]) and writing z in the same layout, member
// after member, to `z`.
template <int kLanes>
void NormaliseLanes(int n, double floor, bool pooled, const int* rows, const double* lane_colors,
                    double* z) {
  Lanes<kLanes> mean[3], variance[3];
  for (int channel = 0; channel < 3; ++channel) {
    mean[channel].setZero();
    variance[channel].setZero();
  }
  for (int m = 0; m < n; ++m) {
    const double* colors = &lane_colors[3L * kLanes * rows[m]];
    for (int channel = 0; channel < 3; ++channel) {
      const auto color = LanesAt<kLanes>(colors + kLanes * channel);
      LanesAt<kLanes>(z + kLanes * (3 * m + channel)) = color;
      mean[channel] += color;
    }
  }
  for (auto& value : mean) value /= n;
  for (int m = 0; m < n; ++m) {
    for (int channel = 0; channel < 3; ++channel) {
      const Lanes<kLanes> difference =
          LanesAt<kLanes>(z + kLanes * (3 * m + channel)) - mean[channel];
      variance[channel] += difference * difference;
    }
  }
  for (auto& value : variance) value /= n;
  if (pooled) {
    const Lanes<kLanes> pooled_variance = (variance[0] + variance[1] + variance[2]) / 3.0;
    for (auto& value : variance) value = pooled_variance;
  }
  Lanes<kLanes> inverse_deviation[3];
  for (int channel = 0; channel < 3; ++channel) {
    inverse_deviation[channel] = 1.0 / (variance[channel] + floor * floor).sqrt();
  }
  for (int m = 0; m < n; ++m) {
    for (int channel = 0; channel < 3; ++channel) {
      auto value = LanesAt<kLanes>(z + kLanes * (3 * m + channel));
      value = (value - mean[channel]) * inverse_deviation[channel];
    }
  }
}

}  // namespace

ConsensusSimilarity::ConsensusSimilarity(const SurfaceGaussians& surface,
                                         const std::vector<EnergyView>& views,
                                         const std::vector<std::vector<int>>& one_rings,
                                         OverlapForm form, double k_max, double reach_sigmas,
                                         const ConsensusOptions& options)
    : PatchAgreementTerm(options, static_cast<int>(views.size())),
      surface_(surface),
      views_(views),
      form_(form),
      reach_sigmas_(reach_sigmas) {
  Require(one_rings.size() == static_cast<size_t>(surface.size()), "consensus similarity",
          "one neighbour list per surface Gaussian expected");
  first_row_.assign(1, 0);
  std::vector<std::vector<int>> rows_of(views.size());
  for (size_t c = 0; c < views.size(); ++c) {
    rows_of[c] = RowsOf(views[c].pairs, surface.size());
    first_row_.push_back(first_row_.back() + static_cast<int>(views[c].pairs.surface_ids.size()));
  }

  row_begin_.push_back(0);
  for (int s = 0; s < surface.size(); ++s) {
    if (static_cast<int>(one_rings[s].size()) < kMinPatchNeighbours) continue;
    std::vector<int> patch = {s};
    patch.insert(patch.end(), one_rings[s].begin(), one_rings[s].end());
    std::vector<int> cameras, rows;
    for (size_t c = 0; c < views.size(); ++c) {
      const auto unseen = [&](int j) { return rows_of[c][j] < 0; };
      if (std::any_of(patch.begin(), patch.end(), unseen)) continue;
      cameras.push_back(static_cast<int>(c));
      for (int j : patch) rows.push_back(first_row_[c] + rows_of[c][j]);
    }
    if (static_cast<int>(cameras.size()) < options_.min_cameras) continue;
    std::vector<double> camera_weights;
    if (options_.view_cosine_power != 0.0) {
      for (int c : cameras) {
        camera_weights.push_back(internal::ViewWeight(
            views[c].camera.ViewCosine(surface.base.col(s), surface.normals.col(s)),
            options_.view_cosine_power));
      }
    }
    AddPatch(s, patch, cameras, camera_weights);
    rows_.insert(rows_.end(), rows.begin(), rows.end());
    row_begin_.push_back(static_cast<long>(rows_.size()));
    max_block_rows_ = std::max(max_block_rows_, static_cast<int>(rows.size()));
  }
  shape_ = Eigen::VectorXd::Zero(surface.size());
  BuildTables(k_max);
  WeighPatches();
}

int ConsensusSimilarity::NumTableNodes(double sigma_hat, double k_max) {
  return static_cast<int>(std::ceil(2.0 * k_max / (sigma_hat / kNodesPerSigma))) + 1;
}

void ConsensusSimilarity::BuildTables(double k_max) {
  num_nodes_ = NumTableNodes(surface_.sigma_hat, k_max);
  node_step_ = 2.0 * k_max / (num_nodes_ - 1);
  node_k0_ = -k_max;
  table_.resize(long(first_row_.back()) * num_nodes_);
  for (size_t c = 0; c < views_.size(); ++c) {
    const int num_rows = static_cast<int>(views_[c].pairs.surface_ids.size());
#pragma omp parallel
    {
      RowImageGaussians paired;
#pragma omp for schedule(dynamic, 16)
      for (int row = 0; row < num_rows; ++row) {
        TabulateRow(views_[c], row, &paired, &table_[(long(first_row_[c]) + row) * num_nodes_]);
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
// precision), so that the loop runs over several image Gaussians at a time: sixteen with
// AVX-512, eight with AVX2, where the processor has them (chosen when the program loads; the build
// itself assumes only SSE2). AVX-512 over AVX2 took a synth_skirt frame's preparation from ~178
// to ~151 ms (BM_PrepareFrame, alternating).
__attribute__((target_clones("avx512f", "avx2", "default"))) OverlapSums SumOverlaps(
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

ConsensusSimilarity::HermiteWeights ConsensusSimilarity::HermiteAt(double k) const {
  // Beyond the table the colour stays at its end value.
  const double x = std::clamp((k - node_k0_) / node_step_, 0.0, num_nodes_ - 1.0);
  HermiteWeights weights;
  weights.node = std::min(static_cast<int>(x), num_nodes_ - 2);
  const double t = x - weights.node, t2 = t * t, t3 = t2 * t;
  weights.value[0] = 2 * t3 - 3 * t2 + 1;
  weights.value[1] = t3 - 2 * t2 + t;
  weights.value[2] = -2 * t3 + 3 * t2;
  weights.value[3] = t3 - t2;
  const bool inside = k > node_k0_ && k < node_k0_ + (num_nodes_ - 1) * node_step_;
  const double per_step = inside ? 1.0 / node_step_ : 0.0;
  weights.derivative[0] = (6 * t2 - 6 * t) * per_step;
  weights.derivative[1] = (3 * t2 - 4 * t + 1) * per_step;
  weights.derivative[2] = (-6 * t2 + 6 * t) * per_step;
  weights.derivative[3] = (3 * t2 - 2 * t) * per_step;
  return weights;
}

Eigen::Vector3d ConsensusSimilarity::Interpolate(int c, int row, double k,
                                                 Eigen::Vector3d* derivative) const {
  const HermiteWeights weights = HermiteAt(k);
  const TableNode* nodes = &table_[(long(first_row_[c]) + row) * num_nodes_ + weights.node];
  Eigen::Vector3d color;
  Blend(weights.value, nodes, color.data());
  if (derivative != nullptr) Blend(weights.derivative, nodes, derivative->data());
  return color;
}

void ConsensusSimilarity::PatchColors(int b, double k, double* colors, double* derivatives) const {
  const int n = PatchSize(b), num_cameras = NumCameras(b);
  const int* rows = &rows_[row_begin_[b]];
  // A member's k, and so its node interval and Hermite weights, is the same in every camera:
  // each camera only reads its two nodes.
  thread_local std::vector<HermiteWeights> weights;
  weights.resize(n);
  const int* members = Members(b);
  const double centre_shape = shape_[members[0]];
  for (int m = 0; m < n; ++m) weights[m] = HermiteAt(k + shape_[members[m]] - centre_shape);
  // Every node pair asked of memory before the first is read: the tables are far larger than the
  // caches, and the reads' waits then overlap.
  for (int a = 0; a < num_cameras; ++a) {
    for (int m = 0; m < n; ++m) {
      const TableNode* nodes = &table_[long(rows[a * n + m]) * num_nodes_ + weights[m].node];
      __builtin_prefetch(nodes);
      __builtin_prefetch(reinterpret_cast<const char*>(nodes + 2) - 1);
    }
  }
  for (int a = 0; a < num_cameras; ++a) {
    for (int m = 0; m < n; ++m) {
      const int i = a * n + m;
      const TableNode* nodes = &table_[long(rows[i]) * num_nodes_ + weights[m].node];
      Blend(weights[m].value, nodes, colors + 3 * i);
      if (derivatives != nullptr) Blend(weights[m].derivative, nodes, derivatives + 3 * i);
    }
  }
}

void ConsensusSimilarity::SetPatchShape(const Eigen::VectorXd& shape) {
  Require(shape.size() == surface_.size(), "consensus similarity",
          "one patch shape entry per surface Gaussian expected");
  shape_ = shape;
}

void ConsensusSimilarity::BlockCosts(const Eigen::VectorXd& k, std::vector<double>* costs) {
  const int num_blocks = static_cast<int>(blocks_.size());
  costs->resize(num_blocks);
  const bool uniform = k.size() > 0 && (k.array() == k[0]).all() && shape_.isZero(0.0);
  if (uniform) {
    std::vector<double> lane_colors;
    UniformCosts<1>(k.data(), costs->data(), num_blocks, &lane_colors);
    return;
  }
  PatchAgreementTerm::BlockCosts(k, costs);
}

void ConsensusSimilarity::UniformBlockCosts(int num_parameters,
                                            const Eigen::VectorXd& displacements,
                                            Eigen::MatrixXd* costs) {
  if (!shape_.isZero(0.0)) {
    SummarisedDataTerm::UniformBlockCosts(num_parameters, displacements, costs);
    return;
  }
  const long num_blocks = static_cast<long>(blocks_.size());
  costs->resize(num_blocks, displacements.size());
  if (num_blocks == 0) return;  // No column to write into: the matrix holds no storage.
  // Eight displacements at a time; the rest one at a time, so that no lane is computed in vain.
  constexpr int kLanes = 8;
  // The row colours live for this call only: at 24 bytes per row and lane, eight lanes take
  // more than half the tables' memory again.
  std::vector<double> lane_colors;
  int j = 0;
  for (; j + kLanes <= displacements.size(); j += kLanes) {
    UniformCosts<kLanes>(&displacements[j], costs->col(j).data(), num_blocks, &lane_colors);
  }
  for (; j < displacements.size(); ++j) {
    UniformCosts<1>(&displacements[j], costs->col(j).data(), num_blocks, &lane_colors);
  }
}

template <int kLanes>
void ConsensusSimilarity::UniformCosts(const double* displacements, double* costs,
                                       long column_stride, std::vector<double>* lane_colors) const {
  // Every row at the same k: one set of Hermite weights for all, per lane.
  HermiteWeights weights[kLanes];
  for (int lane = 0; lane < kLanes; ++lane) weights[lane] = HermiteAt(displacements[lane]);
  const int num_rows = first_row_.back(), num_blocks = static_cast<int>(blocks_.size());
  lane_colors->resize(3L * kLanes * num_rows);
  // One parallel region for both loops: on a busy machine each region's start and barrier can
  // wait a time slice for a thread.
#pragma omp parallel
  {
#pragma omp for schedule(static)
    for (int row = 0; row < num_rows; ++row) {
      const TableNode* row_nodes = &table_[long(row) * num_nodes_];
      double* colors = &(*lane_colors)[3L * kLanes * row];
      for (int lane = 0; lane < kLanes; ++lane) {
        double color[3];
        Blend(weights[lane].value, row_nodes + weights[lane].node, color);
        for (int channel = 0; channel < 3; ++channel)
          colors[channel * kLanes + lane] = color[channel];
      }
    }
    std::vector<double> scratch(3L * kLanes * max_block_rows_);
#pragma omp for schedule(dynamic, 64)
    for (int b = 0; b < num_blocks; ++b) {
      double block_costs[kLanes];
      UniformCostsOfBlock<kLanes>(b, lane_colors->data(), scratch.data(), block_costs);
      for (int lane = 0; lane < kLanes; ++lane) costs[b + lane * column_stride] = block_costs[lane];
    }
  }
}

template <int kLanes>
void ConsensusSimilarity::UniformCostsOfBlock(int b, const double* lane_colors, double* scratch,
                                              double costs[kLanes]) const {
  const int n = PatchSize(b), num_cameras = NumCameras(b);
  const int* rows = &rows_[row_begin_[b]];
  const int stride = 3 * kLanes * n;  // From one camera's patch to the next.
  for (int a = 0; a < num_cameras; ++a) {
    NormaliseLanes<kLanes>(n, options_.contrast_floor, !options_.gain_per_channel, rows + n * a,
                           lane_colors, scratch + stride * a);
  }
  // PlainResiduals' against the (weighted) mean, in place, then the sum of their squares.
  const Eigen::Vector3d weight = scale_ * weights_[b];
  const double* camera_weights = CameraWeights(b);
  const auto camera_weight = [&](int a) {
    return camera_weights != nullptr ? camera_weights[a] : 1.0;
  };
  thread_local std::vector<double> roots;  // Of the cameras' weights.
  roots.resize(num_cameras);
  double total_weight = 0.0;
  for (int a = 0; a < num_cameras; ++a) {
    roots[a] = std::sqrt(camera_weight(a));
    total_weight += camera_weight(a);
  }
  for (int m = 0; m < n; ++m) {
    for (int channel = 0; channel < 3; ++channel) {
      double* values = scratch + kLanes * (3 * m + channel);
      Lanes<kLanes> mean = Lanes<kLanes>::Zero();
      for (int a = 0; a < num_cameras; ++a) {
        mean += camera_weight(a) * LanesAt<kLanes>(values + stride * a);
      }
      for (int a = 0; a < num_cameras; ++a) {
        auto value = LanesAt<kLanes>(values + stride * a);
        value = roots[a] * weight[channel] * (value - mean / total_weight);
      }
    }
  }
  Lanes<kLanes> squared_norm = Lanes<kLanes>::Zero();
  for (int i = 0; i < 3 * num_cameras * n; ++i) {
    squared_norm += LanesAt<kLanes>(scratch + kLanes * i).square();
  }
  const double c2 = LossScale(b);
  for (int lane = 0; lane < kLanes; ++lane) {
    BlockSummary plain;
    plain.squared_norm = squared_norm[lane];
    costs[lane] = Robustify(c2, plain, false).squared_norm;
  }
}

}  // namespace finecap
