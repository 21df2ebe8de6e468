#include "finecap/solvers/sweep.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "finecap/util/error.h"

namespace finecap {

namespace {

// costs(s, j): the data cost of Gaussian s with every Gaussian at displacement j, or, with a
// `base`, moved by displacement j from it, summed over the data terms that offer sweep costs
// (SweepCosts).
Eigen::MatrixXd CostsPerGaussian(FrameEnergy* energy, const Eigen::VectorXd& displacements,
                                 const Eigen::VectorXd* base = nullptr) {
  const int n = energy->num_parameters();
  Eigen::MatrixXd costs = Eigen::MatrixXd::Zero(n, displacements.size());
  Eigen::MatrixXd block_costs;
  for (int t = 0; t < energy->num_data_terms(); ++t) {
    DataTerm& term = energy->data_term(t);
    SweepCosts* sweep = term.sweep_costs();
    if (sweep == nullptr) continue;
    if (base == nullptr) {
      sweep->UniformBlockCosts(n, displacements, &block_costs);
    } else {
      term.BlockCostsAround(*base, displacements, &block_costs);
    }
    const auto& blocks = term.residual_blocks();
    // Blocks may share a Gaussian (the paper's similarity): summed in one thread.
    for (int j = 0; j < displacements.size(); ++j) {
      for (int b = 0; b < static_cast<int>(blocks.size()); ++b) {
        for (int s : blocks[b].parameters)
          costs(s, j) += block_costs(b, j) / blocks[b].parameters.size();
      }
    }
  }
  return costs;
}

// The samples, evenly spaced over [-k_max, k_max], an odd number of them (k = 0 among them) when
// max_step_sigmas sets their number.
Eigen::VectorXd SweepDisplacements(const SweepOptions& options, double k_max, double sigma_hat) {
  int samples = options.samples;
  if (options.max_step_sigmas > 0.0) {
    const double half = std::ceil(k_max / (options.max_step_sigmas * sigma_hat));
    samples = std::max(samples,
                       1 + 2 * static_cast<int>(std::min(half, 0.5 * SweepOptions::kMaxSamples)));
  }
  return Eigen::VectorXd::LinSpaced(samples, -k_max, k_max);
}

// The position of a cost curve's lowest sample `best` (of `displacements`, evenly spaced) refined
// to the vertex of the parabola through it and its neighbours.
double SubSamplePosition(const Eigen::Ref<const Eigen::RowVectorXd>& costs,
                         const Eigen::VectorXd& displacements, int best) {
  const int last = static_cast<int>(displacements.size()) - 1;
  if (best == 0 || best == last) return displacements[best];
  const double c0 = costs[best - 1], c1 = costs[best], c2 = costs[best + 1];
  const double curvature = c0 - 2.0 * c1 + c2;
  if (!(curvature > 0.0)) return displacements[best];
  const double step = displacements[1] - displacements[0];
  return displacements[best] + 0.5 * step * (c0 - c2) / curvature;
}

// The distance within which all but `share` of `distances` lie: its largest entry with fewer than
// share * size() entries above it. Infinite for none.
double Reach(std::vector<double>* distances, double share) {
  const int n = static_cast<int>(distances->size());
  if (n == 0) return std::numeric_limits<double>::infinity();
  // The most entries that may lie above it: the largest count below share * n.
  const int above = std::clamp(static_cast<int>(std::ceil(share * n)) - 1, 0, n - 1);
  const auto at = distances->begin() + (n - 1 - above);
  std::nth_element(distances->begin(), at, distances->end());
  return *at;
}

// How far past a window's edge a displacement still counts as inside it: LinSpaced's rounding.
double EdgeTolerance(const Eigen::Ref<const Eigen::VectorXd>& displacements) {
  return 1e-9 * (displacements[displacements.size() - 1] - displacements[0]);
}

}  // namespace

int WindowedMinimum(const Eigen::Ref<const Eigen::RowVectorXd>& costs,
                    const Eigen::Ref<const Eigen::VectorXd>& displacements, double window,
                    double* searched) {
  const int n = static_cast<int>(costs.size());
  const double tolerance = EdgeTolerance(displacements);
  // The samples within `reach` of k = 0: [first, last].
  const auto samples_within = [&](double reach, int* first, int* last) {
    *first = 0;
    *last = n - 1;
    while (*first < n - 1 && displacements[*first] < -reach - tolerance) ++*first;
    while (*last > *first && displacements[*last] > reach + tolerance) --*last;
  };
  for (double reach = window;; reach *= 2.0) {
    if (searched != nullptr) *searched = reach;
    int first = 0, last = 0;
    samples_within(reach, &first, &last);
    int best = 0;
    const double low = costs.segment(first, last - first + 1).minCoeff(&best);
    best += first;
    const bool at_lower_end = best == first && first > 0;
    const bool at_upper_end = best == last && last + 1 < n;
    if (!at_lower_end && !at_upper_end) return best;
    int wide_first = 0, wide_last = 0;
    samples_within(2.0 * reach, &wide_first, &wide_last);
    const double beyond = at_lower_end ? costs.segment(wide_first, first - wide_first).minCoeff()
                                       : costs.segment(last + 1, wide_last - last).minCoeff();
    if (!(beyond < low)) return best;
  }
}

double CostUniqueness(const Eigen::Ref<const Eigen::RowVectorXd>& costs,
                      const Eigen::Ref<const Eigen::VectorXd>& displacements, int chosen,
                      double distinct, double searched) {
  const double own = costs[chosen];
  const double tolerance = EdgeTolerance(displacements);
  double rival = std::numeric_limits<double>::infinity();
  for (int j = 0; j < costs.size(); ++j) {
    if (std::abs(displacements[j] - displacements[chosen]) > distinct &&
        std::abs(displacements[j]) <= searched + tolerance) {
      rival = std::min(rival, costs[j]);
    }
  }
  if (rival == std::numeric_limits<double>::infinity()) return 1.0;
  std::vector<double> sorted(costs.begin(), costs.end());
  const auto middle = sorted.begin() + sorted.size() / 2;
  std::nth_element(sorted.begin(), middle, sorted.end());
  const double height = *middle - own;
  if (!(height > 0.0)) return 0.0;
  return std::clamp((rival - own) / height, 0.0, 1.0);
}

SweepResult Sweep(FrameEnergy* energy, const SweepOptions& options) {
  options.Check();
  const int n = energy->num_parameters();
  SweepResult result;
  result.k = Eigen::VectorXd::Zero(n);
  if (options.samples == 0 || n == 0) return result;
  const double k_max = energy->layout().bound;
  const double sigma_hat = energy->surface().sigma_hat;
  const Eigen::VectorXd displacements = SweepDisplacements(options, k_max, sigma_hat);
  const double window = options.window_sigmas > 0.0 ? options.window_sigmas * sigma_hat : k_max;
  Eigen::MatrixXd costs = CostsPerGaussian(energy, displacements);
  energy->regularizer().AverageOverNeighbours(options.smoothing_rounds, &costs);
  const int last = static_cast<int>(displacements.size()) - 1;
  // One column: the uniqueness is averaged over the neighbours as the costs were.
  Eigen::MatrixXd uniqueness = Eigen::MatrixXd::Ones(n, 1);
  int at_ends = 0;
  std::vector<double> confident_starts;  // |k| of the confident Gaussians.
  for (int s = 0; s < n; ++s) {
    // A Gaussian whose curve is flat (no block reaches it, nor its neighbours' costs) has no
    // best displacement: it stays where the coarse mesh puts it rather than at -k_max.
    if (costs.row(s).minCoeff() == costs.row(s).maxCoeff()) continue;
    double searched = 0.0;
    const int best = WindowedMinimum(costs.row(s), displacements, window, &searched);
    // Where the images cannot decide k a curve at an end says nothing of the range.
    const bool confident = energy->confidence().size() != n || energy->confidence()[s] >= 0.5;
    at_ends += confident && (best == 0 || best == last);
    result.k[s] = SubSamplePosition(costs.row(s), displacements, best);
    uniqueness(s, 0) = CostUniqueness(costs.row(s), displacements, best,
                                      kDistinctMinimumSigmas * sigma_hat, searched);
    if (confident) confident_starts.push_back(std::abs(result.k[s]));
  }
  result.share_at_ends = static_cast<double>(at_ends) / n;
  result.reach = Reach(&confident_starts, options.narrow_share);
  energy->regularizer().AverageOverNeighbours(options.smoothing_rounds, &uniqueness);
  result.uniqueness = uniqueness.col(0);
  return result;
}

Eigen::VectorXd SweepInitialization(FrameEnergy* energy, const SweepOptions& options) {
  return Sweep(energy, options).k;
}

Eigen::VectorXd SweepAround(FrameEnergy* energy, const Eigen::VectorXd& k, double range,
                            double step, int smoothing_rounds) {
  Require(range > 0.0 && step > 0.0, "SweepAround", "range and step must be positive");
  const int half = static_cast<int>(std::ceil(range / step - 1e-9));
  const Eigen::VectorXd offsets = Eigen::VectorXd::LinSpaced(2 * half + 1, -range, range);
  Eigen::MatrixXd costs = CostsPerGaussian(energy, offsets, &k);
  energy->regularizer().AverageOverNeighbours(smoothing_rounds, &costs);
  const double bound = energy->layout().bound;
  Eigen::VectorXd moved = k;
  for (int s = 0; s < moved.size(); ++s) {
    if (costs.row(s).minCoeff() == costs.row(s).maxCoeff()) continue;
    int best = 0;
    costs.row(s).minCoeff(&best);
    moved[s] = std::clamp(k[s] + SubSamplePosition(costs.row(s), offsets, best), -bound, bound);
  }
  return moved;
}

}  // namespace finecap
