// A frame's energy as a list of data terms: several terms are summed in its value, its gradient,
// its least-squares cost and the rows of the Ceres adapter, and each capability a term offers
// (or does not) is honoured by the solvers: reduced rows or full residual blocks, the sweep's
// costs, the hook between passes.
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <ceres/gradient_checker.h>
#include <ceres/problem.h>
#include <gtest/gtest.h>

#include "energy_fixture.h"
#include "finecap/energy/data_term.h"
#include "finecap/energy/frame_energy.h"
#include "finecap/solvers/solver.h"
#include "finecap/solvers/sweep.h"
#include "finecap/util/error.h"
#include "solvers/ceres_cost_functions.h"

namespace finecap {
namespace {

// A least-squares data term of its own, beside the registry's: each unknown k_s is held near c_s
// by one block of two residuals, a_s (k_s - c_s) and b (k_s - c_s)^2 (curved, so that its
// Gauss-Newton model is not exact). Which capabilities it offers is chosen.
class TargetTerm : public SummarisedDataTerm, public PassHook {
 public:
  struct Offers {
    bool summaries = true;
    bool sweep = true;
    bool hook = false;
  };

  TargetTerm(int n, Offers offers) : offers_(offers), a_(n), c_(n) {
    for (int s = 0; s < n; ++s) {
      a_[s] = 20.0 + 5.0 * std::cos(0.9 * s);
      c_[s] = 0.003 * std::sin(0.7 * s);
      blocks_.push_back({{s}, 2});
    }
  }

  double Evaluate(const Eigen::VectorXd& k, Eigen::VectorXd* gradient) const override {
    if (gradient != nullptr) gradient->resize(k.size());
    double sum = 0.0;
    for (int s = 0; s < k.size(); ++s) {
      double r[2], j[2];
      Residuals(s, k[s], r, j);
      sum += r[0] * r[0] + r[1] * r[1];
      if (gradient != nullptr) (*gradient)[s] = -(j[0] * r[0] + j[1] * r[1]);
    }
    return -0.5 * sum;
  }
  const std::vector<ResidualBlock>& residual_blocks() const override { return blocks_; }
  void PrepareResiduals(const Eigen::VectorXd& k, bool /*with_jacobians*/) override { k_ = k; }
  void BlockResiduals(int block, double* residuals, double* jacobian) const override {
    double j[2];
    Residuals(block, k_[block], residuals, j);
    if (jacobian != nullptr) std::copy_n(j, 2, jacobian);
  }
  bool IsLeastSquares() const override { return true; }
  bool ReadsPairLists() const override { return false; }

  BlockSummaries* block_summaries() override { return offers_.summaries ? this : nullptr; }
  SweepCosts* sweep_costs() override { return offers_.sweep ? this : nullptr; }
  PassHook* pass_hook() override { return offers_.hook ? this : nullptr; }
  void EndOfPass(const Eigen::VectorXd& k) override { last_pass_ = k; }

  Eigen::VectorXd last_pass_;

 private:
  void Residuals(int s, double k, double* r, double* j) const {
    constexpr double kCurve = 2000.0;
    const double d = k - c_[s];
    r[0] = a_[s] * d;
    r[1] = kCurve * d * d;
    j[0] = a_[s];
    j[1] = 2.0 * kCurve * d;
  }

  Offers offers_;
  Eigen::VectorXd a_, c_;
  std::vector<ResidualBlock> blocks_;
  Eigen::VectorXd k_;
};

EnergyOptions Options(const std::string& similarity) {
  EnergyOptions options;
  EXPECT_TRUE(StringToEnum(similarity, &options.similarity)) << similarity;
  options.k_max = 0.01;
  options.w_reg = 1e-3;
  options.w_prior = 1e-4;
  return options;
}

Eigen::VectorXd SomeK(int n) {
  Eigen::VectorXd k(n);
  for (int s = 0; s < n; ++s) k[s] = 0.002 * std::sin(1.7 * s);
  return k;
}

class DataTermsTest : public ::testing::TestWithParam<std::string> {};

// Value, gradient and least-squares cost of an energy of two data terms are those of the
// registry's term alone plus the added term's.
TEST_P(DataTermsTest, TwoTermsAreSummed) {
  const EnergyScene scene = MakeEnergyScene({0.0, 0.8, 1.3}, 3, 31);
  FrameEnergy energy(scene.surface, scene.cameras, scene.neighbourhoods, Options(GetParam()));
  const int n = energy.num_parameters();
  const Eigen::VectorXd k = SomeK(n);
  Eigen::VectorXd gradient_alone;
  double data_alone = 0.0, quadratic_alone = 0.0;
  const double e_alone = energy.Evaluate(k, &gradient_alone, &data_alone, &quadratic_alone);
  const double cost_alone = LeastSquaresCost(&energy, k);
  const bool least_squares_alone = energy.IsLeastSquares();

  auto added = std::make_unique<TargetTerm>(n, TargetTerm::Offers{});
  TargetTerm* term = added.get();
  energy.AddDataTerm(std::move(added));
  ASSERT_EQ(energy.num_data_terms(), 2);
  Eigen::VectorXd term_gradient;
  const double term_value = term->Evaluate(k, &term_gradient);
  ASSERT_LT(term_value, -1e-6);  // The added term has something to add.

  Eigen::VectorXd gradient;
  double data = 0.0, quadratic = 0.0;
  const double e = energy.Evaluate(k, &gradient, &data, &quadratic);
  const double tolerance = 1e-12 * (1.0 + std::abs(data_alone) + std::abs(term_value));
  EXPECT_NEAR(data, data_alone + term_value, tolerance);
  EXPECT_EQ(quadratic, quadratic_alone);
  EXPECT_NEAR(e, e_alone + term_value, tolerance);
  EXPECT_LE((gradient - gradient_alone - term_gradient).norm(),
            1e-12 * (1.0 + gradient_alone.norm() + term_gradient.norm()));
  // The added term is least-squares: its cost is minus its value.
  EXPECT_NEAR(LeastSquaresCost(&energy, k), cost_alone - term_value, tolerance);
  EXPECT_EQ(energy.IsLeastSquares(), least_squares_alone);
}

// The Ceres adapter's row of each surface Gaussian holds the summaries of every term that
// reduces its blocks, summed: its curvature is theirs plus the pull's, its cost their sum of
// squares plus the pull's, each term's summary as that term alone gives it.
TEST_P(DataTermsTest, TheAdapterSumsTheRowsOfEveryTerm) {
  const EnergyScene scene = MakeEnergyScene({0.0, 0.8, 1.3}, 3, 31);
  FrameEnergy energy(scene.surface, scene.cameras, scene.neighbourhoods, Options(GetParam()));
  const int n = energy.num_parameters();
  auto added = std::make_unique<TargetTerm>(n, TargetTerm::Offers{});
  TargetTerm* term = added.get();
  energy.AddDataTerm(std::move(added));
  DataTerm& similarity = energy.data_term(0);

  Eigen::VectorXd k = SomeK(n);
  FrameCostFunctions cost_functions;
  ceres::Problem::Options problem_options;
  problem_options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  cost_functions.AddResidualBlocks(&energy, false, FrameCostFunctions::Layout::kPerGaussian, &k,
                                   &problem);
  GaussianModelRows* rows = cost_functions.model_rows();
  ASSERT_NE(rows, nullptr);
  ASSERT_EQ(rows->size(), n);
  double seconds = 0.0;
  SharedEvaluationCallback callback(DataTermsOf(&energy), &k, &seconds);
  callback.PrepareRowsToo(rows);
  callback.PrepareForEvaluation(true, true);

  // Each term's summary of unknown s, the term prepared alone.
  std::vector<BlockSummary> of_similarity(n), of_term(n);
  std::vector<bool> found(n, false);
  similarity.block_summaries()->PrepareBlockSummaries(k);
  for (int b = 0; b < static_cast<int>(similarity.residual_blocks().size()); ++b) {
    const std::vector<int>& parameters = similarity.residual_blocks()[b].parameters;
    if (parameters.size() != 1 || found[parameters[0]]) continue;
    found[parameters[0]] = true;  // The first block of k_s alone is the row's.
    of_similarity[parameters[0]] = similarity.block_summaries()->BlockSummaryOf(b);
  }
  term->PrepareBlockSummaries(k);
  for (int s = 0; s < n; ++s) of_term[s] = term->BlockSummaryOf(s);
  callback.Forget();
  callback.PrepareForEvaluation(true, true);

  int with_both = 0;
  for (int s = 0; s < n; ++s) {
    const BlockSummary summary = rows->Summary(s);
    const BlockSummary& a = of_similarity[s];
    const BlockSummary& b = of_term[s];
    const double scale =
        1e-12 * (1.0 + a.squared_norm + b.squared_norm + a.curvature + b.curvature);
    EXPECT_NEAR(summary.squared_norm, a.squared_norm + b.squared_norm, scale) << s;
    EXPECT_NEAR(summary.gradient, a.gradient + b.gradient, scale) << s;
    EXPECT_NEAR(summary.curvature, a.curvature + b.curvature, scale) << s;
    const double p = std::max(0.0, energy.pull_curvature()[s]);
    EXPECT_NEAR(rows->Length(s) * rows->Length(s), a.curvature + b.curvature + p, scale) << s;
    with_both += a.curvature > 0.0 && b.curvature > 0.0;
  }
  if (GetParam() != "paper") {
    EXPECT_GT(with_both, n / 4);
    // One block per Gaussian and the remainder: the added term stands in no block of its own.
    EXPECT_EQ(problem.NumResidualBlocks(), n + 1);
  }
}

// A term that does not reduce its blocks has them added to the problem as they are: one more
// block per unknown, the same least-squares problem, so a solve takes the same steps (to
// rounding) and reports the least-squares cost of the energy.
TEST_P(DataTermsTest, ATermThatDoesNotReduceAddsItsBlocksAsTheyAre) {
  const EnergyScene scene = MakeEnergyScene({0.0, 0.8, 1.3}, 3, 31);
  SolverOptions options;
  options.max_iterations = 5;
  options.function_tolerance = 1e-12;
  options.num_threads = 2;
  // J^T J for every block, reduced or not (the secant models the reduced rows alone), and exact
  // steps.
  options.curvature = CurvatureModel::kGaussNewton;
  options.linear_solver = LinearSolverType::kSparseNormalCholesky;
  std::vector<Eigen::VectorXd> solutions;
  std::vector<int> blocks;
  for (bool reduces : {true, false}) {
    FrameEnergy energy(scene.surface, scene.cameras, scene.neighbourhoods, Options(GetParam()));
    const int n = energy.num_parameters();
    TargetTerm::Offers offers;
    offers.summaries = reduces;
    energy.AddDataTerm(std::make_unique<TargetTerm>(n, offers));
    Eigen::VectorXd k = SomeK(n);
    {
      Eigen::VectorXd state = k;
      FrameCostFunctions cost_functions;
      ceres::Problem::Options problem_options;
      problem_options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
      ceres::Problem problem(problem_options);
      cost_functions.AddResidualBlocks(&energy, false, FrameCostFunctions::Layout::kPerGaussian,
                                       &state, &problem);
      blocks.push_back(problem.NumResidualBlocks());
    }
    const double start_cost = LeastSquaresCost(&energy, k);
    const SolverSummary summary = Solve(&energy, options, &k);
    if (energy.IsLeastSquares()) {
      EXPECT_NEAR(summary.ls_cost_start, start_cost, 1e-12 * start_cost) << reduces;
    }
    EXPECT_LT(summary.ls_cost_end, start_cost) << reduces;
    solutions.push_back(k);
  }
  EXPECT_EQ(blocks[1] - blocks[0], static_cast<int>(solutions[0].size()));
  EXPECT_LE((solutions[1] - solutions[0]).norm(), 1e-9 * solutions[0].norm());
}

// The added term's blocks pass Ceres' gradient checker, as the registry's do (solver_test.cc).
TEST(DataTermsTest, TheAddedTermsBlocksPassTheGradientChecker) {
  TargetTerm term(12, TargetTerm::Offers{});
  const Eigen::VectorXd k = SomeK(12);
  ceres::NumericDiffOptions numeric;
  numeric.ridders_relative_initial_step_size = 1e-5;
  for (int b = 0; b < 12; ++b) {
    const IsolatedDataBlockCost cost(&term, b, k);
    const ceres::GradientChecker checker(
        &cost, static_cast<const std::vector<const ceres::Manifold*>*>(nullptr), numeric);
    const double value = k[b];
    const double* parameters[] = {&value};
    ceres::GradientChecker::ProbeResults results;
    EXPECT_TRUE(checker.Probe(parameters, 1e-6, &results)) << results.error_log;
  }
}

// The sweep reads only the terms that offer its costs; the hook between passes reaches only the
// terms that offer it.
TEST(DataTermsTest, TheSweepAndThePassesAskEachTermWhatItOffers) {
  const EnergyScene scene = MakeEnergyScene({0.0, 0.8, 1.3}, 3, 31);
  FrameEnergy energy(scene.surface, scene.cameras, scene.neighbourhoods, Options("surface_color"));
  const int n = energy.num_parameters();
  SweepOptions sweep;
  sweep.samples = 9;
  const Eigen::VectorXd alone = SweepInitialization(&energy, sweep);
  ASSERT_GT(alone.norm(), 0.0);
  EXPECT_FALSE(energy.HasPassHooks());

  TargetTerm::Offers offers;
  offers.sweep = false;
  offers.hook = true;
  auto silent = std::make_unique<TargetTerm>(n, offers);
  TargetTerm* hooked = silent.get();
  energy.AddDataTerm(std::move(silent));
  EXPECT_EQ(SweepInitialization(&energy, sweep), alone);
  ASSERT_TRUE(energy.HasPassHooks());
  const Eigen::VectorXd k = SomeK(n);
  energy.EndOfPass(k);
  EXPECT_EQ(hooked->last_pass_, k);
  EXPECT_THROW(energy.EndOfPass(Eigen::VectorXd::Zero(n + 1)), Error);

  // A term that offers the sweep's costs moves its start.
  energy.AddDataTerm(std::make_unique<TargetTerm>(n, TargetTerm::Offers{}));
  EXPECT_GT((SweepInitialization(&energy, sweep) - alone).norm(), 1e-6);
}

INSTANTIATE_TEST_SUITE_P(Similarities, DataTermsTest,
                         ::testing::Values("surface_color", "consensus", "paper"));

}  // namespace
}  // namespace finecap
