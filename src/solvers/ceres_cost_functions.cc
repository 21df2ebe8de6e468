#include "solvers/ceres_cost_functions.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <utility>
#include <vector>

#include <Eigen/QR>

#include "finecap/util/error.h"
#include "solvers/solvers_internal.h"

namespace finecap {

SharedEvaluationCallback::SharedEvaluationCallback(std::vector<DataTerm*> terms,
                                                   const Eigen::VectorXd* k, double* seconds)
    : terms_(std::move(terms)), k_(k), seconds_(seconds) {}

void SharedEvaluationCallback::PrepareForEvaluation(bool evaluate_jacobians,
                                                    bool new_evaluation_point) {
  // Each step's candidate is evaluated for its cost alone and, once the step is taken, again
  // with Jacobians at the same point (Ceres says so); a step is mostly taken, so one preparation
  // with Jacobians serves both. Comparing the point itself also catches a point Ceres evaluates
  // again without saying so.
  const bool new_point =
      new_evaluation_point && !(prepared_.size() == k_->size() && prepared_ == *k_);
  const bool rows_wanted = evaluate_jacobians && rows_ != nullptr;
  if (!new_point && (!rows_wanted || rows_prepared_)) return;
  const internal::Stopwatch clock;
  if (new_point) {
    for (DataTerm* term : terms_) {
      if (BlockSummaries* summaries = term->block_summaries()) {
        summaries->PrepareBlockSummaries(*k_);
      } else {
        term->PrepareResiduals(*k_, true);
      }
    }
    prepared_ = *k_;
    rows_prepared_ = false;
  }
  if (rows_wanted && !rows_prepared_) {
    rows_->Prepare(*k_);
    rows_prepared_ = true;
  }
  *seconds_ += clock.Seconds();
}

void SharedEvaluationCallback::Rebind(std::vector<DataTerm*> terms) {
  terms_ = std::move(terms);
  Forget();
}

std::vector<DataTerm*> DataTermsOf(FrameEnergy* energy) {
  std::vector<DataTerm*> terms;
  for (int i = 0; i < energy->num_data_terms(); ++i) terms.push_back(&energy->data_term(i));
  return terms;
}

DataBlockCost::DataBlockCost(const DataTerm& term, int block) : term_(term), block_(block) {
  const DataTerm::ResidualBlock& info = term.residual_blocks()[block];
  set_num_residuals(info.num_residuals);
  mutable_parameter_block_sizes()->assign(info.parameters.size(), 1);
}

bool DataBlockCost::Evaluate(double const* const* /*parameters*/, double* residuals,
                             double** jacobians) const {
  if (jacobians == nullptr) {
    term_.BlockResiduals(block_, residuals, nullptr);
    return true;
  }
  // The term writes a row-major residuals x parameters matrix; Ceres wants one column per
  // parameter block.
  const int num_parameters = static_cast<int>(parameter_block_sizes().size());
  thread_local std::vector<double> jacobian;
  jacobian.resize(static_cast<size_t>(num_residuals()) * num_parameters);
  term_.BlockResiduals(block_, residuals, jacobian.data());
  for (int p = 0; p < num_parameters; ++p) {
    if (jacobians[p] == nullptr) continue;
    for (int r = 0; r < num_residuals(); ++r) jacobians[p][r] = jacobian[r * num_parameters + p];
  }
  return true;
}

ReducedDataBlockCost::ReducedDataBlockCost(const DataTerm& term, const BlockSummaries* summaries,
                                           int block, bool secant)
    : term_(term), summaries_(summaries), block_(block), full_(term, block), secant_(secant) {
  const DataTerm::ResidualBlock& info = term.residual_blocks()[block];
  num_full_residuals_ = info.num_residuals;
  const int num_parameters = static_cast<int>(info.parameters.size());
  Require(num_parameters > 1 || summaries != nullptr, "ReducedDataBlockCost",
          "a block of one parameter is reduced from its term's summaries");
  set_num_residuals(num_parameters == 1 ? 2 : std::min(num_full_residuals_, num_parameters + 1));
  mutable_parameter_block_sizes()->assign(num_parameters, 1);
}

bool ReducedDataBlockCost::Evaluate(double const* const* parameters, double* residuals,
                                    double** jacobians) const {
  const int p = static_cast<int>(parameter_block_sizes().size());
  if (p == 1) {
    ReducedOneParameterRows(summaries_->BlockSummaryOf(block_), parameters[0][0], secant_,
                            &curvature_, residuals, jacobians);
    return true;
  }
  const int m = num_full_residuals_;
  thread_local Eigen::VectorXd r;
  thread_local Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> jacobian;
  r.resize(m);
  if (m == num_residuals()) return full_.Evaluate(parameters, residuals, jacobians);
  std::fill_n(residuals, num_residuals(), 0.0);
  if (jacobians == nullptr) {
    term_.BlockResiduals(block_, r.data(), nullptr);
    residuals[0] = r.norm();
    return true;
  }
  jacobian.resize(m, p);
  term_.BlockResiduals(block_, r.data(), jacobian.data());
  const double squared_norm = r.squaredNorm();
  Eigen::MatrixXd reduced = Eigen::MatrixXd::Zero(p + 1, p);  // [R; 0].
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(jacobian);
  const Eigen::VectorXd along = (qr.householderQ().transpose() * r).head(p);  // Q^T r.
  reduced.topRows(p) = qr.matrixQR().topRows(p).triangularView<Eigen::Upper>();
  for (int i = 0; i < p; ++i) residuals[i] = along[i];
  // What of r no step can reduce; rounding may make the difference a hair negative.
  residuals[p] = std::sqrt(std::max(0.0, squared_norm - along.squaredNorm()));
  for (int q = 0; q < p; ++q) {
    if (jacobians[q] == nullptr) continue;
    for (int i = 0; i <= p; ++i) jacobians[q][i] = reduced(i, q);
  }
  return true;
}

double BlockCurvature::At(double k, const BlockSummary& summary, bool secant) {
  if (!secant) return summary.curvature;
  // Steps shorter than this (metres) are rounding: their secant is noise.
  constexpr double kMinSpan = 1e-9;
  const bool moved = !has_last_ || std::abs(k - last_k_) > kMinSpan;
  double curvature = summary.curvature;
  if (has_last_ && moved) {
    const double secant_curvature = (summary.gradient - last_gradient_) / (k - last_k_);
    curvature = std::clamp(secant_curvature, kMinSecantFactor * summary.curvature,
                           kMaxSecantFactor * summary.curvature);
    // J^T J >= g^2 / |r|^2 always (Cauchy-Schwarz); a lower h must not go below it.
    if (summary.squared_norm > 0.0) {
      curvature = std::max(curvature, summary.gradient * summary.gradient / summary.squared_norm);
    }
  }
  if (moved) {
    has_last_ = true;
    last_k_ = k;
    last_gradient_ = summary.gradient;
  }
  return curvature;
}

void ReducedOneParameterRows(const BlockSummary& summary, double k, bool secant,
                             BlockCurvature* curvature, double* residuals, double** jacobians) {
  if (jacobians == nullptr) {
    residuals[0] = std::sqrt(summary.squared_norm);
    residuals[1] = 0.0;
    return;
  }
  // R = sqrt(h) and Q^T r = J^T r / R, h = J^T J but for the secant.
  const double length = std::sqrt(curvature->At(k, summary, secant));
  residuals[0] = length > 0.0 ? summary.gradient / length : 0.0;
  // What of r no step can reduce; rounding may make the difference a hair negative.
  residuals[1] = std::sqrt(std::max(0.0, summary.squared_norm - residuals[0] * residuals[0]));
  if (jacobians[0] != nullptr) {
    jacobians[0][0] = length;
    jacobians[0][1] = 0.0;
  }
}

IsolatedDataBlockCost::IsolatedDataBlockCost(DataTerm* term, int block, const Eigen::VectorXd& k)
    : DataBlockCost(*term, block), mutable_term_(term), k_(k) {}

bool IsolatedDataBlockCost::Evaluate(double const* const* parameters, double* residuals,
                                     double** jacobians) const {
  Eigen::VectorXd k = k_;
  const std::vector<int>& ids = term_.residual_blocks()[block_].parameters;
  for (size_t p = 0; p < ids.size(); ++p) k[ids[p]] = parameters[p][0];
  mutable_term_->PrepareResiduals(k, jacobians != nullptr);
  return DataBlockCost::Evaluate(parameters, residuals, jacobians);
}

SmoothnessBlockCost::SmoothnessBlockCost(double prior_root, std::vector<Neighbour> neighbours,
                                         int num_free, double prior_target)
    : prior_root_(prior_root), prior_target_(prior_target), neighbours_(std::move(neighbours)) {
  set_num_residuals(NumRows(prior_root_, static_cast<int>(neighbours_.size())));
  mutable_parameter_block_sizes()->assign(1 + num_free, 1);
}

bool SmoothnessBlockCost::Evaluate(double const* const* parameters, double* residuals,
                                   double** jacobians) const {
  Rows(prior_root_, prior_target_, neighbours_.data(), static_cast<int>(neighbours_.size()),
       static_cast<int>(parameter_block_sizes().size()), parameters, residuals, jacobians, 0);
  return true;
}

void SmoothnessBlockCost::Rows(double prior_root, double prior_target, const Neighbour* neighbours,
                               int num_neighbours, int num_parameters,
                               double const* const* parameters, double* residuals,
                               double** jacobians, int first_row) {
  const int num_rows = NumRows(prior_root, num_neighbours);
  const auto jacobian = [&](int p) {
    return jacobians != nullptr && jacobians[p] != nullptr ? jacobians[p] + first_row : nullptr;
  };
  for (int p = 0; p < num_parameters; ++p) {
    if (double* column = jacobian(p)) std::fill_n(column, num_rows, 0.0);
  }
  const double k = parameters[0][0];
  double* own = jacobian(0);
  int r = 0;
  if (prior_root > 0.0) {
    residuals[r] = prior_root * (k - prior_target);
    if (own != nullptr) own[r] = prior_root;
    ++r;
  }
  for (int j = 0; j < num_neighbours; ++j) {
    const Neighbour& neighbour = neighbours[j];
    const double other = neighbour.parameter >= 0 ? parameters[neighbour.parameter][0] : 0.0;
    residuals[r] = neighbour.coefficient * (k - other);
    if (own != nullptr) own[r] = neighbour.coefficient;
    if (neighbour.parameter >= 0) {
      if (double* column = jacobian(neighbour.parameter)) column[r] = -neighbour.coefficient;
    }
    ++r;
  }
}

int GaussianModelRows::Add(int parameter, double prior, double target) {
  Gaussian gaussian;
  gaussian.parameter = parameter;
  gaussian.first_block = static_cast<int>(blocks_.size());
  gaussian.prior = prior;
  gaussian.target = target;
  gaussians_.push_back(gaussian);
  return size() - 1;
}

void GaussianModelRows::AddBlock(int i, const BlockSummaries* summaries, int block) {
  Gaussian& gaussian = gaussians_[i];
  if (gaussian.num_blocks == 0) gaussian.first_block = static_cast<int>(blocks_.size());
  Require(gaussian.first_block + gaussian.num_blocks == static_cast<int>(blocks_.size()),
          "GaussianModelRows::AddBlock", "blocks are added Gaussian after Gaussian");
  blocks_.push_back({summaries, block});
  ++gaussian.num_blocks;
}

void GaussianModelRows::ClearBlocks() {
  blocks_.clear();
  for (Gaussian& gaussian : gaussians_) gaussian.num_blocks = 0;
}

BlockSummary GaussianModelRows::Summary(int i) const {
  const Gaussian& gaussian = gaussians_[i];
  if (gaussian.num_blocks == 0) return {};
  // The first block's summary itself, then the others added to it.
  const Block* block = &blocks_[gaussian.first_block];
  BlockSummary sum = block->summaries->BlockSummaryOf(block->block);
  for (int j = 1; j < gaussian.num_blocks; ++j) {
    ++block;
    const BlockSummary& more = block->summaries->BlockSummaryOf(block->block);
    sum.squared_norm += more.squared_norm;
    sum.gradient += more.gradient;
    sum.curvature += more.curvature;
  }
  return sum;
}

void GaussianModelRows::Prepare(const Eigen::VectorXd& k) {
  double remainder = 0.0;
  for (int i = 0; i < size(); ++i) {
    Gaussian& gaussian = gaussians_[i];
    const BlockSummary summary = Summary(i);
    const double k_s = k[gaussian.parameter];
    const double from_target = k_s - gaussian.target;
    const double curvature = gaussian.curvature.At(k_s, summary, secant_) + gaussian.prior;
    gaussian.length = std::sqrt(curvature);
    gaussian.row = gaussian.length > 0.0
                       ? (summary.gradient + gaussian.prior * from_target) / gaussian.length
                       : 0.0;
    // (g + p d)^2 / (h + p) <= |r|^2 + p d^2, d = k - t (Cauchy-Schwarz, h >= g^2 / |r|^2):
    // rounding may make the difference a hair negative.
    remainder += std::max(0.0, summary.squared_norm + gaussian.prior * from_target * from_target -
                                   gaussian.row * gaussian.row);
  }
  remainder_norm_ = std::sqrt(remainder);
}

void GaussianModelRows::ForgetHistories() {
  for (Gaussian& gaussian : gaussians_) gaussian.curvature.Forget();
}

double GaussianModelRows::Norm(int i, double k) const {
  const Gaussian& gaussian = gaussians_[i];
  const double from_target = k - gaussian.target;
  return std::sqrt(Summary(i).squared_norm + gaussian.prior * from_target * from_target);
}

SurfaceGaussianCost::SurfaceGaussianCost(const GaussianModelRows& rows, int i,
                                         const SmoothnessBlockCost::Neighbour* neighbours,
                                         int num_neighbours, int num_free)
    : rows_(rows), index_(i), neighbours_(neighbours), num_neighbours_(num_neighbours) {
  set_num_residuals(1 + SmoothnessBlockCost::NumRows(0.0, num_neighbours_));
  mutable_parameter_block_sizes()->assign(1 + num_free, 1);
}

bool SurfaceGaussianCost::Evaluate(double const* const* parameters, double* residuals,
                                   double** jacobians) const {
  const int num_parameters = static_cast<int>(parameter_block_sizes().size());
  // Each parameter block's Jacobian is one column (all blocks are 1-D): the Gaussian's row first,
  // zero but in k_s's column, then the smoothness rows.
  if (jacobians == nullptr) {
    residuals[0] = rows_.Norm(index_, parameters[0][0]);
  } else {
    residuals[0] = rows_.Row(index_);
    if (jacobians[0] != nullptr) jacobians[0][0] = rows_.Length(index_);
    for (int p = 1; p < num_parameters; ++p) {
      if (jacobians[p] != nullptr) jacobians[p][0] = 0.0;
    }
  }
  SmoothnessBlockCost::Rows(0.0, 0.0, neighbours_, num_neighbours_, num_parameters, parameters,
                            residuals + 1, jacobians, 1);
  return true;
}

RemainderCost::RemainderCost(const GaussianModelRows& rows) : rows_(rows) {
  set_num_residuals(1);
  mutable_parameter_block_sizes()->assign(1, 1);
}

bool RemainderCost::Evaluate(double const* const* /*parameters*/, double* residuals,
                             double** jacobians) const {
  residuals[0] = jacobians == nullptr ? 0.0 : rows_.RemainderNorm();
  if (jacobians != nullptr && jacobians[0] != nullptr) jacobians[0][0] = 0.0;
  return true;
}

namespace {

// The smoothness residuals of every surface Gaussian, in one place: Gaussian s's pairs are
// neighbours[begin[s]] to neighbours[begin[s + 1] - 1], in the regulariser's order, and the
// free ones read k_other[j] (-1 for a neighbour fixed at 0). A handful of allocations, not a few
// for each of the ~10k Gaussians: the problem is built anew for each frame, on the thread that
// solves it (on synth_skirt's frames building it took ~7 instead of ~9 ms, medians).
struct SmoothnessRows {
  std::vector<double> prior_root;  // sqrt(h_s), or 0 for no prior residual.
  std::vector<int> begin;
  std::vector<SmoothnessBlockCost::Neighbour> neighbours;
  std::vector<int> other;

  int num_neighbours(int s) const { return begin[s + 1] - begin[s]; }
  bool empty(int s) const { return prior_root[s] == 0.0 && num_neighbours(s) == 0; }
  // k_s, then each free neighbour of s in order: the parameter blocks s's residuals read.
  void ParameterBlocks(int s, Eigen::VectorXd* k, std::vector<double*>* blocks) const {
    blocks->assign(1, &(*k)[s]);
    for (int j = begin[s]; j < begin[s + 1]; ++j) {
      if (other[j] >= 0) blocks->push_back(&(*k)[other[j]]);
    }
  }
};

// Each difference of neighbours goes to its first Gaussian, `a`.
SmoothnessRows SmoothnessRowsOfEachGaussian(const FrameEnergy& energy, int num_gaussians) {
  const Eigen::VectorXd& prior = energy.pull_curvature();
  SmoothnessRows rows;
  rows.prior_root.resize(num_gaussians);
  for (int s = 0; s < num_gaussians; ++s) {
    rows.prior_root[s] = prior[s] > 0.0 ? std::sqrt(prior[s]) : 0.0;
  }
  rows.begin.assign(num_gaussians + 1, 0);
  const std::vector<Difference>& pairs = energy.differences();
  for (const Difference& pair : pairs) ++rows.begin[pair.a + 1];
  std::partial_sum(rows.begin.begin(), rows.begin.end(), rows.begin.begin());
  rows.neighbours.resize(pairs.size());
  rows.other.resize(pairs.size());
  std::vector<int> next(rows.begin.begin(), rows.begin.end() - 1);
  std::vector<int> num_free(num_gaussians, 0);
  for (const Difference& pair : pairs) {
    const int j = next[pair.a]++;
    rows.neighbours[j].coefficient = pair.root;
    rows.neighbours[j].parameter = pair.b >= 0 ? ++num_free[pair.a] : -1;
    rows.other[j] = pair.b;
  }
  return rows;
}

}  // namespace

void FrameCostFunctions::AddResidualBlocks(FrameEnergy* energy, bool secant, Layout layout,
                                           Eigen::VectorXd* k, ceres::Problem* problem) {
  const double k_max = energy->layout().bound;
  const int num_gaussians = static_cast<int>(k->size());
  for (int s = 0; s < num_gaussians; ++s) {
    problem->AddParameterBlock(&(*k)[s], 1);
    problem->SetParameterLowerBound(&(*k)[s], 0, -k_max);
    problem->SetParameterUpperBound(&(*k)[s], 0, k_max);
  }
  const int num_terms = energy->num_data_terms();
  std::vector<std::vector<int>> merged(num_terms);
  for (int t = 0; t < num_terms; ++t) {
    merged[t] = AddDataBlocks(&energy->data_term(t), secant, layout, k, problem);
  }
  SmoothnessRows rows = SmoothnessRowsOfEachGaussian(*energy, num_gaussians);
  neighbours_ = std::move(rows.neighbours);
  const bool per_gaussian = layout == Layout::kPerGaussian;
  rebindable_ = per_gaussian && reduced_.empty() && full_.empty() && num_gaussians > 0;
  k_max_ = k_max;
  neighbour_begin_ = rows.begin;
  neighbour_other_ = rows.other;
  model_rows_ = std::make_unique<GaussianModelRows>(secant);
  const Eigen::VectorXd& prior = energy->pull_curvature();
  const Eigen::VectorXd& target = energy->pull_target();
  std::vector<double*> parameter_blocks;
  for (int s = 0; s < num_gaussians; ++s) {
    if (!per_gaussian && rows.empty(s)) continue;
    rows.ParameterBlocks(s, k, &parameter_blocks);
    const int num_free = static_cast<int>(parameter_blocks.size()) - 1;
    const SmoothnessBlockCost::Neighbour* neighbours = neighbours_.data() + rows.begin[s];
    if (per_gaussian) {
      const int row = model_rows_->Add(s, std::max(0.0, prior[s]), target[s]);
      AddSummaryBlocks(row, s, merged, energy);
      surface_gaussians_.emplace_back(*model_rows_, row, neighbours, rows.num_neighbours(s),
                                      num_free);
      problem->AddResidualBlock(&surface_gaussians_.back(), nullptr, parameter_blocks);
    } else {
      smoothness_.emplace_back(rows.prior_root[s],
                               std::vector<SmoothnessBlockCost::Neighbour>(
                                   neighbours, neighbours + rows.num_neighbours(s)),
                               num_free, target[s]);
      problem->AddResidualBlock(&smoothness_.back(), nullptr, parameter_blocks);
    }
  }
  if (model_rows_->size() == 0) {
    model_rows_.reset();
    return;
  }
  remainder_ = std::make_unique<RemainderCost>(*model_rows_);
  problem->AddResidualBlock(remainder_.get(), nullptr, &(*k)[0]);
}

std::vector<int> FrameCostFunctions::OneBlockPerGaussian(DataTerm* term, int num_gaussians) {
  if (term->block_summaries() == nullptr) return {};
  std::vector<int> block_of(num_gaussians, -1);
  for (int b = 0; b < static_cast<int>(term->residual_blocks().size()); ++b) {
    const std::vector<int>& parameters = term->residual_blocks()[b].parameters;
    if (parameters.size() != 1 || block_of[parameters[0]] >= 0) return {};
    block_of[parameters[0]] = b;
  }
  return block_of;
}

void FrameCostFunctions::AddSummaryBlocks(int row, int s,
                                          const std::vector<std::vector<int>>& block_of,
                                          FrameEnergy* energy) {
  for (int t = 0; t < static_cast<int>(block_of.size()); ++t) {
    if (block_of[t].empty() || block_of[t][s] < 0) continue;
    model_rows_->AddBlock(row, energy->data_term(t).block_summaries(), block_of[t][s]);
  }
}

bool FrameCostFunctions::Rebind(FrameEnergy* energy) {
  const int num_gaussians = model_rows_ != nullptr ? model_rows_->size() : 0;
  if (!rebindable_ || energy->num_parameters() != num_gaussians ||
      energy->layout().bound != k_max_) {
    return false;
  }
  const int num_terms = energy->num_data_terms();
  std::vector<std::vector<int>> block_of(num_terms);
  for (int t = 0; t < num_terms; ++t) {
    block_of[t] = OneBlockPerGaussian(&energy->data_term(t), num_gaussians);
    if (block_of[t].empty() && !energy->data_term(t).residual_blocks().empty()) return false;
  }
  SmoothnessRows rows = SmoothnessRowsOfEachGaussian(*energy, num_gaussians);
  if (rows.begin != neighbour_begin_ || rows.other != neighbour_other_) return false;
  // In place: every SurfaceGaussianCost holds its neighbours' address.
  std::copy(rows.neighbours.begin(), rows.neighbours.end(), neighbours_.begin());
  model_rows_->ClearBlocks();
  const Eigen::VectorXd& prior = energy->pull_curvature();
  const Eigen::VectorXd& target = energy->pull_target();
  for (int s = 0; s < num_gaussians; ++s) {
    model_rows_->Set(s, std::max(0.0, prior[s]), target[s]);
    AddSummaryBlocks(s, s, block_of, energy);
  }
  return true;
}

std::vector<int> FrameCostFunctions::AddDataBlocks(DataTerm* term, bool secant, Layout layout,
                                                   Eigen::VectorXd* k, ceres::Problem* problem) {
  const BlockSummaries* summaries = term->block_summaries();
  std::vector<int> merged(k->size(), -1);
  std::vector<double*> parameter_blocks;
  for (int b = 0; b < static_cast<int>(term->residual_blocks().size()); ++b) {
    const std::vector<int>& parameters = term->residual_blocks()[b].parameters;
    const bool one = parameters.size() == 1;
    if (layout == Layout::kPerGaussian && one && summaries != nullptr &&
        merged[parameters[0]] < 0) {
      merged[parameters[0]] = b;
      continue;
    }
    parameter_blocks.clear();
    for (int s : parameters) parameter_blocks.push_back(&(*k)[s]);
    if (one && summaries == nullptr) {
      full_.emplace_back(*term, b);
      problem->AddResidualBlock(&full_.back(), nullptr, parameter_blocks);
    } else {
      reduced_.emplace_back(*term, summaries, b, secant);
      problem->AddResidualBlock(&reduced_.back(), nullptr, parameter_blocks);
    }
  }
  return merged;
}

void FrameCostFunctions::ForgetHistories() {
  for (const ReducedDataBlockCost& cost : reduced_) cost.ForgetHistory();
  if (model_rows_ != nullptr) model_rows_->ForgetHistories();
}

}  // namespace finecap
