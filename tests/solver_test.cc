#include "finecap/solvers/solver.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <utility>

#include <ceres/gradient_checker.h>
#include <ceres/problem.h>
#include <gtest/gtest.h>

#include "energy/terms/consensus/consensus_similarity.h"
#include "energy_fixture.h"
#include "finecap/util/error.h"
#include "solvers/ceres_cost_functions.h"
#include "solvers/solvers_internal.h"

namespace finecap {
namespace {

EnergyOptions Options(const std::string& similarity, const std::string& overlap) {
  EnergyOptions options;
  EXPECT_TRUE(StringToEnum(similarity, &options.similarity)) << similarity;
  EXPECT_TRUE(StringToEnum(overlap, &options.overlap)) << overlap;
  options.k_max = 0.01;
  options.w_reg = 1e-3;
  return options;
}

bool CheckGradient(const ceres::CostFunction& cost, const std::vector<double>& values,
                   std::string* error) {
  ceres::NumericDiffOptions numeric;
  // k is in metres and often 0: the checker (Ridders) starts from an absolute step of this size.
  numeric.ridders_relative_initial_step_size = 1e-5;
  const ceres::GradientChecker checker(
      &cost, static_cast<const std::vector<const ceres::Manifold*>*>(nullptr), numeric);
  std::vector<const double*> parameters;
  for (const double& value : values) parameters.push_back(&value);
  ceres::GradientChecker::ProbeResults results;
  const bool ok = checker.Probe(parameters.data(), 1e-6, &results);
  *error = results.error_log;
  return ok;
}

class CeresCostTest : public ::testing::TestWithParam<EnergyForm> {};

// The scene the cost-function tests share: three cameras up to 75 degrees, and a k that varies
// from Gaussian to Gaussian.
struct CostScene {
  CostScene(const std::string& similarity, const std::string& overlap)
      : scene(MakeEnergyScene({0.0, 0.8, 1.3}, 3, 31)),
        energy(scene.surface, scene.cameras, scene.neighbourhoods, Options(similarity, overlap)),
        k(energy.num_parameters()) {
    for (int s = 0; s < k.size(); ++s) k[s] = 0.002 * std::sin(1.7 * s);
  }
  EnergyScene scene;
  FrameEnergy energy;
  Eigen::VectorXd k;
};

// Every kind of least-squares residual, checked by ceres::GradientChecker against numeric
// differences, including cameras at 75 degrees (near grazing).
TEST_P(CeresCostTest, SimilarityBlocksPassTheGradientChecker) {
  const auto [similarity, overlap] = GetParam();
  CostScene scene(similarity, overlap);
  FrameEnergy& energy = scene.energy;
  const Eigen::VectorXd& k = scene.k;
  DataTerm& term = energy.data_term(0);
  const int num_blocks = static_cast<int>(term.residual_blocks().size());
  int checked = 0, failed = 0;
  for (int b = 0; b < num_blocks; b += std::max(1, num_blocks / 40)) {
    const IsolatedDataBlockCost cost(&term, b, k);
    std::vector<double> values;
    for (int s : term.residual_blocks()[b].parameters) values.push_back(k[s]);
    std::string error;
    if (!CheckGradient(cost, values, &error)) {
      ++failed;
      ADD_FAILURE() << "block " << b << ": " << error;
    }
    ++checked;
  }
  EXPECT_GE(checked, 20);
  EXPECT_EQ(failed, 0);
}

INSTANTIATE_TEST_SUITE_P(AllForms, CeresCostTest, AllEnergyForms(), EnergyFormName);

TEST(CeresCostTest, SmoothnessBlocksPassTheGradientChecker) {
  std::string error;
  // A prior, two free neighbours (parameters 1 and 2) and one fixed at 0.
  const SmoothnessBlockCost full(0.7, {{1, 3.5}, {-1, 1.5}, {2, 2.0}}, 2);
  EXPECT_EQ(full.num_residuals(), 4);
  EXPECT_TRUE(CheckGradient(full, {0.004, -0.002, 0.001}, &error)) << error;
  // No prior: one residual per neighbour.
  const SmoothnessBlockCost pairs_only(0.0, {{1, 3.5}}, 1);
  EXPECT_EQ(pairs_only.num_residuals(), 1);
  EXPECT_TRUE(CheckGradient(pairs_only, {0.004, -0.002}, &error)) << error;
  // A prior alone.
  const SmoothnessBlockCost prior_only(0.7, {}, 0);
  EXPECT_EQ(prior_only.num_residuals(), 1);
  EXPECT_TRUE(CheckGradient(prior_only, {0.004}, &error)) << error;
  // A prior towards the input as given, 3 mm off k = 0: its residual vanishes there.
  const SmoothnessBlockCost prior_off(0.7, {{1, 3.5}}, 1, 0.003);
  EXPECT_TRUE(CheckGradient(prior_off, {0.004, -0.002}, &error)) << error;
  const double at_target[] = {0.003, 0.003};
  const double* parameters[] = {&at_target[0], &at_target[1]};
  double residuals[2] = {1.0, 1.0};
  ASSERT_TRUE(prior_off.Evaluate(parameters, residuals, nullptr));
  EXPECT_EQ(residuals[0], 0.0);
  EXPECT_EQ(residuals[1], 0.0);
}

// A surface Gaussian's merged block (its row of GaussianModelRows, with a prior, and three
// neighbours, one fixed at 0) and the remainder: their gradient J^T r, with the secant's model,
// against central differences of the cost 1/2 (|r|^2 + p k_s^2) + the smoothness terms, the
// similarity prepared at each point; the cost with Jacobians (the row and the remainder) equals
// the cost alone. The row is the reduced one, whose Jacobian is not its derivative
// (GaussianModelRows), so the gradient is what is checked; the smoothness rows match
// SmoothnessBlockCost's without a prior, and the row is zero in the neighbours' columns.
TEST_P(CeresCostTest, SurfaceGaussianBlocksHaveTheGradientOfTheirCost) {
  const auto [similarity, overlap] = GetParam();
  CostScene scene(similarity, overlap);
  DataTerm& term = scene.energy.data_term(0);
  Eigen::VectorXd point = scene.k;
  double seconds = 0.0;
  const std::vector<SmoothnessBlockCost::Neighbour> neighbours = {{1, 3.5}, {-1, 1.5}, {2, 2.0}};
  const SmoothnessBlockCost smoothness(0.0, neighbours, 2);
  constexpr double kPrior = 0.49;
  const int num_blocks = static_cast<int>(term.residual_blocks().size());
  int checked = 0;
  for (int b = 0; b < num_blocks; b += std::max(1, num_blocks / 20)) {
    if (term.residual_blocks()[b].parameters.size() != 1) continue;
    const int s = term.residual_blocks()[b].parameters[0];
    GaussianModelRows rows(true);
    const int row = rows.Add(s, kPrior);
    rows.AddBlock(row, term.block_summaries(), b);
    const RemainderCost remainder(rows);
    SharedEvaluationCallback callback({&term}, &point, &seconds);
    callback.PrepareRowsToo(&rows);
    const SurfaceGaussianCost cost(rows, row, neighbours.data(),
                                   static_cast<int>(neighbours.size()), 2);
    ASSERT_EQ(cost.num_residuals(), 1 + smoothness.num_residuals());
    ASSERT_EQ(cost.parameter_block_sizes().size(), 3u);
    const int m = cost.num_residuals();
    std::vector<double> values = {scene.k[s], 0.0011, -0.0023};
    std::vector<const double*> parameters;
    for (const double& value : values) parameters.push_back(&value);
    // Moves the point to `values`: the similarity prepared at k with k_s = values[0].
    auto move = [&]() {
      point = scene.k;
      point[s] = values[0];
      callback.PrepareForEvaluation(false, true);
    };
    // 1/2 |r|^2 at `values`, the cost alone, as Ceres evaluates a step's candidate.
    auto half_squared_norm = [&]() {
      move();
      Eigen::VectorXd r(m);
      double rest = 1.0;
      EXPECT_TRUE(cost.Evaluate(parameters.data(), r.data(), nullptr));
      EXPECT_TRUE(remainder.Evaluate(parameters.data(), &rest, nullptr));
      EXPECT_EQ(rest, 0.0);
      return 0.5 * r.squaredNorm();
    };
    // Two points with Jacobians, so that the secant models the curvature at the second.
    values[0] += 0.0002;
    move();
    callback.PrepareForEvaluation(true, false);
    values[0] -= 0.0002;
    const double cost_alone = half_squared_norm();
    callback.PrepareForEvaluation(true, false);
    Eigen::VectorXd r(m);
    std::vector<Eigen::VectorXd> columns(3, Eigen::VectorXd::Constant(m, std::nan("")));
    std::vector<double*> jacobians = {columns[0].data(), columns[1].data(), columns[2].data()};
    ASSERT_TRUE(cost.Evaluate(parameters.data(), r.data(), jacobians.data()));
    double rest = 0.0, rest_jacobian = std::nan("");
    double* rest_jacobians[] = {&rest_jacobian};
    ASSERT_TRUE(remainder.Evaluate(parameters.data(), &rest, rest_jacobians));
    EXPECT_EQ(rest_jacobian, 0.0);
    EXPECT_NEAR(0.5 * (r.squaredNorm() + rest * rest), cost_alone, 1e-12 * (1.0 + cost_alone))
        << "block " << b;

    Eigen::VectorXd smoothness_r(smoothness.num_residuals());
    std::vector<Eigen::VectorXd> smoothness_columns(3, Eigen::VectorXd(smoothness_r.size()));
    std::vector<double*> smoothness_jacobians = {
        smoothness_columns[0].data(), smoothness_columns[1].data(), smoothness_columns[2].data()};
    ASSERT_TRUE(
        smoothness.Evaluate(parameters.data(), smoothness_r.data(), smoothness_jacobians.data()));
    EXPECT_EQ(r.tail(smoothness_r.size()), smoothness_r) << "block " << b;
    for (int p = 0; p < 3; ++p) {
      EXPECT_EQ(columns[p].tail(smoothness_r.size()), smoothness_columns[p]) << "block " << b;
      if (p > 0) {
        EXPECT_EQ(columns[p][0], 0.0) << "block " << b;
      }
    }
    // The row's curvature is the similarity's (the secant's, within its bounds) plus the prior's.
    const BlockSummary& summary = term.block_summaries()->BlockSummaryOf(b);
    EXPECT_GE(columns[0][0] * columns[0][0],
              BlockCurvature::kMinSecantFactor * summary.curvature + kPrior - 1e-12)
        << "block " << b;
    EXPECT_LE(columns[0][0] * columns[0][0],
              BlockCurvature::kMaxSecantFactor * summary.curvature + kPrior + 1e-12)
        << "block " << b;

    constexpr double kStep = 1e-7;  // Metres; k is a few millimetres.
    for (int p = 0; p < 3; ++p) {
      const double analytic = columns[p].dot(r);
      const double value = values[p];
      values[p] = value + kStep;
      const double above = half_squared_norm();
      values[p] = value - kStep;
      const double below = half_squared_norm();
      values[p] = value;
      const double numeric = (above - below) / (2.0 * kStep);
      EXPECT_NEAR(analytic, numeric, 1e-5 * (std::abs(numeric) + columns[p].norm() * r.norm()))
          << "block " << b << ", parameter " << p;
    }
    ++checked;
  }
  if (similarity != "paper") {
    EXPECT_GE(checked, 10);
  }
}

// The rows of GaussianModelRows are prepared once a point, where Ceres first asks for Jacobians
// there, and not at a point evaluated for its cost alone: a second preparation at the same point
// would take the secant's history for a step of length zero.
TEST(CeresCostTest, TheCallbackPreparesTheRowsOncePerPointWithJacobians) {
  CostScene scene("consensus", "printed");
  DataTerm& term = scene.energy.data_term(0);
  Eigen::VectorXd point = scene.k;
  double seconds = 0.0;
  GaussianModelRows rows(true);
  const int num_blocks = static_cast<int>(term.residual_blocks().size());
  for (int b = 0; b < num_blocks; ++b) {
    rows.AddBlock(rows.Add(term.residual_blocks()[b].parameters[0], 0.0), term.block_summaries(),
                  b);
  }
  ASSERT_GT(rows.size(), 10);
  SharedEvaluationCallback callback({&term}, &point, &seconds);
  callback.PrepareRowsToo(&rows);
  auto lengths = [&] {
    std::vector<double> values;
    for (int i = 0; i < rows.size(); ++i) values.push_back(rows.Length(i));
    return values;
  };
  callback.PrepareForEvaluation(false, true);
  EXPECT_EQ(lengths(), std::vector<double>(rows.size(), 0.0)) << "prepared for a cost alone";
  callback.PrepareForEvaluation(true, false);
  for (int i = 0; i < rows.size(); ++i) {
    EXPECT_NEAR(rows.Length(i) * rows.Length(i),
                term.block_summaries()->BlockSummaryOf(i).curvature,
                1e-12 * (1.0 + term.block_summaries()->BlockSummaryOf(i).curvature));
  }
  point.array() += 0.0003;
  callback.PrepareForEvaluation(false, true);
  callback.PrepareForEvaluation(true, false);
  const std::vector<double> secant = lengths();
  int differ = 0;
  for (int i = 0; i < rows.size(); ++i) {
    differ +=
        std::abs(secant[i] * secant[i] - term.block_summaries()->BlockSummaryOf(i).curvature) >
        1e-6 * term.block_summaries()->BlockSummaryOf(i).curvature;
  }
  EXPECT_GT(differ, 0) << "the secant's curvature is J^T J's everywhere";
  callback.PrepareForEvaluation(true, false);
  callback.PrepareForEvaluation(true, true);
  EXPECT_EQ(lengths(), secant);
}

// One residual block per surface Gaussian (its similarity block of one parameter and its
// smoothness residuals together) is the same least-squares problem as the blocks apart: the same
// residuals in fewer blocks, and a few Levenberg-Marquardt iterations end at the same k and cost,
// to rounding.
TEST_P(CeresCostTest, PerGaussianBlocksTakeTheStepsOfSeparateBlocks) {
  const auto [similarity, overlap] = GetParam();
  EnergyScene scene = MakeEnergyScene({0.0, 0.8, 1.3}, 3, 31);
  EnergyOptions energy_options = Options(similarity, overlap);
  energy_options.w_prior = 1e-4;
  FrameEnergy energy(scene.surface, scene.cameras, scene.neighbourhoods, energy_options);
  Eigen::VectorXd start(energy.num_parameters());
  for (int s = 0; s < start.size(); ++s) start[s] = 0.002 * std::sin(1.7 * s);

  using Layout = FrameCostFunctions::Layout;
  auto count_blocks = [&](Layout layout, int* num_residuals) {
    Eigen::VectorXd k = start;
    FrameCostFunctions cost_functions;
    ceres::Problem::Options problem_options;
    problem_options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    ceres::Problem problem(problem_options);
    cost_functions.AddResidualBlocks(&energy, true, layout, &k, &problem);
    *num_residuals = problem.NumResiduals();
    return problem.NumResidualBlocks();
  };
  int separate_residuals = 0, merged_residuals = 0;
  const int separate_blocks = count_blocks(Layout::kSeparate, &separate_residuals);
  const int merged_blocks = count_blocks(Layout::kPerGaussian, &merged_residuals);
  EXPECT_LT(merged_blocks, separate_blocks);
  if (similarity != "paper") {
    // One block per Gaussian and the remainder; one row per Gaussian instead of the similarity's
    // two and the prior's.
    EXPECT_EQ(merged_blocks, energy.num_parameters() + 1);
    int with_row = 0, with_prior = 0;
    for (const DataTerm::ResidualBlock& block : energy.data_term(0).residual_blocks()) {
      ++with_row;
      with_prior += energy.pull_curvature()[block.parameters[0]] > 0.0;
    }
    EXPECT_EQ(merged_residuals, separate_residuals - with_row - with_prior + 1);
  }

  SolverOptions options;
  options.max_iterations = 5;
  options.function_tolerance = 1e-12;
  options.num_threads = 2;
  auto solve = [&](Layout layout, Eigen::VectorXd* k) {
    *k = start;
    SolverSummary summary;
    internal::SolveWithCeres(&energy, options, k, &summary, layout);
    return summary;
  };
  Eigen::VectorXd k_separate, k_merged;
  const SolverSummary separate = solve(Layout::kSeparate, &k_separate);
  const SolverSummary merged = solve(Layout::kPerGaussian, &k_merged);
  ASSERT_GT(separate.iterations, 1);
  EXPECT_EQ(merged.iterations, separate.iterations);
  ASSERT_GT((k_separate - start).norm(), 1e-3 * start.norm()) << "the solve did not move";
  EXPECT_LE((k_merged - k_separate).norm(), 1e-9 * k_separate.norm());
  EXPECT_NEAR(merged.ls_cost_end, separate.ls_cost_end, 1e-9 * separate.ls_cost_end);
}

// A FrameSolver keeps its Ceres problem from one pass to the next, while the consensus energy's
// patch shape changes in between: each pass must take the steps of a problem built afresh (the
// point prepared last and the secant histories, which belonged to the energy before, forgotten).
TEST(FrameSolverTest, PassesOnOneProblemTakeTheStepsOfFreshProblems) {
  EnergyScene scene = MakeEnergyScene({0.0, 0.8, 1.3}, 3, 31);
  FrameEnergy energy(scene.surface, scene.cameras, scene.neighbourhoods,
                     Options("consensus", "exact"));
  auto* consensus = dynamic_cast<ConsensusSimilarity*>(&energy.data_term(0));
  ASSERT_NE(consensus, nullptr);
  Eigen::VectorXd start(energy.num_parameters());
  for (int s = 0; s < start.size(); ++s) start[s] = 0.002 * std::sin(1.7 * s);
  const Eigen::VectorXd flat = Eigen::VectorXd::Zero(start.size());
  SolverOptions options;
  options.max_iterations = 6;
  options.function_tolerance = 1e-12;
  options.num_threads = 2;

  // Three passes: the input surface's patches, then patches shaped like the last result, twice.
  auto passes = [&](bool one_problem, std::vector<SolverSummary>* summaries) {
    Eigen::VectorXd k = start;
    consensus->SetPatchShape(flat);
    FrameSolver solver(&energy, options);
    for (int pass = 0; pass < 3; ++pass) {
      if (pass > 0) consensus->SetPatchShape(k);
      summaries->push_back(one_problem ? solver.Solve(&k) : Solve(&energy, options, &k));
    }
    return k;
  };
  std::vector<SolverSummary> fresh, kept;
  const Eigen::VectorXd k_fresh = passes(false, &fresh);
  const Eigen::VectorXd k_kept = passes(true, &kept);
  ASSERT_GT((k_fresh - start).norm(), 1e-3 * start.norm()) << "the solves did not move";
  for (int pass = 0; pass < 3; ++pass) {
    EXPECT_EQ(kept[pass].iterations, fresh[pass].iterations) << pass;
    EXPECT_EQ(kept[pass].evaluations, fresh[pass].evaluations) << pass;
    EXPECT_NEAR(kept[pass].ls_cost_start, fresh[pass].ls_cost_start,
                1e-12 * fresh[pass].ls_cost_start)
        << pass;
    EXPECT_NEAR(kept[pass].ls_cost_end, fresh[pass].ls_cost_end, 1e-12 * fresh[pass].ls_cost_end)
        << pass;
    // Each pass reports its own share of the similarity's work, a part of its evaluation.
    EXPECT_GT(kept[pass].seconds_similarity, 0.0) << pass;
    EXPECT_LE(kept[pass].seconds_similarity, kept[pass].seconds_evaluation) << pass;
  }
  EXPECT_LE((k_kept - k_fresh).norm(), 1e-12 * k_fresh.norm());
  consensus->SetPatchShape(flat);
}

// A workspace carries Ceres' problem from one frame's energy to the next of the same structure
// (other image Gaussians, so other similarity values and blocks): each frame takes the steps a
// problem of its own takes, reading its own energy, not the last one's. An energy of another
// structure (no regulariser) gets a problem of its own, and takes its steps too.
TEST(FrameSolverTest, FramesInOneWorkspaceTakeTheStepsOfProblemsOfTheirOwn) {
  EnergyOptions energy_options = Options("consensus", "printed");
  energy_options.w_prior = 1e-4;
  EnergyOptions without_regularizer = energy_options;
  without_regularizer.w_reg = 0.0;
  std::vector<EnergyScene> scenes;
  scenes.push_back(MakeEnergyScene({0.0, 0.8, 1.3}, 3, 31));
  scenes.push_back(MakeEnergyScene({0.0, 0.8, 1.3}, 3, 47));
  std::vector<std::unique_ptr<FrameEnergy>> frames;
  for (const EnergyOptions& options : {energy_options, energy_options, without_regularizer}) {
    const EnergyScene& scene = scenes[frames.size() % 2];
    frames.push_back(
        std::make_unique<FrameEnergy>(scene.surface, scene.cameras, scene.neighbourhoods, options));
  }
  ASSERT_EQ(frames[0]->num_parameters(), frames[1]->num_parameters());
  Eigen::VectorXd start(frames[0]->num_parameters());
  for (int s = 0; s < start.size(); ++s) start[s] = 0.002 * std::sin(1.7 * s);
  SolverOptions options;
  options.max_iterations = 5;
  options.function_tolerance = 1e-12;
  options.num_threads = 2;

  SolverWorkspace workspace;
  std::vector<Eigen::VectorXd> solved;
  const std::vector<int> built = {1, 1, 2};
  for (size_t f = 0; f < frames.size(); ++f) {
    Eigen::VectorXd own = start, shared = start;
    const SolverSummary alone = Solve(frames[f].get(), options, &own);
    const SolverSummary taken_over =
        FrameSolver(frames[f].get(), options, &workspace).Solve(&shared);
    EXPECT_EQ(workspace.problems_built(), built[f]) << "frame " << f;
    ASSERT_GT((own - start).norm(), 1e-3 * start.norm()) << "frame " << f << " did not move";
    EXPECT_EQ(taken_over.iterations, alone.iterations) << "frame " << f;
    EXPECT_NEAR(taken_over.ls_cost_end, alone.ls_cost_end, 1e-12 * alone.ls_cost_end)
        << "frame " << f;
    EXPECT_LE((shared - own).norm(), 1e-12 * own.norm()) << "frame " << f;
    solved.push_back(own);
  }
  // The frames differ: a problem reading the last frame's energy would not take their steps.
  EXPECT_GT((solved[1] - solved[0]).norm(), 1e-3 * solved[0].norm());
}

// A frame's passes and levels add up: every count and time of the work, and nothing of where the
// solve started or ended.
TEST(SolverSummaryTest, AddWorkSumsCountsAndTimes) {
  SolverSummary total;
  total.iterations = 3;
  total.evaluations = 4;
  total.seconds = 0.5;
  total.seconds_evaluation = 0.25;
  total.seconds_linear_solver = 0.125;
  total.seconds_similarity = 0.0625;
  total.energy_start = -2.0;
  SolverSummary pass = total;
  pass.energy_start = -1.0;
  total.AddWork(pass);
  EXPECT_EQ(total.iterations, 6);
  EXPECT_EQ(total.evaluations, 8);
  EXPECT_EQ(total.seconds, 1.0);
  EXPECT_EQ(total.seconds_evaluation, 0.5);
  EXPECT_EQ(total.seconds_linear_solver, 0.25);
  EXPECT_EQ(total.seconds_similarity, 0.125);
  EXPECT_EQ(total.energy_start, -2.0);
}

// The problem Ceres is given (similarity blocks, one smoothness block per Gaussian) has the cost
// LeastSquaresCost computes term by term, with the regulariser and a prior (towards an input off
// k = 0) both present: every
// pair and every prior is in exactly one block.
TEST(SolverTest, CeresProblemHasTheLeastSquaresCost) {
  EnergyScene scene = MakeEnergyScene({0.0, 0.6, -0.6}, 3, 23);
  EnergyOptions energy_options = Options("surface_color", "printed");
  energy_options.w_prior = 1e-4;
  // The input as given off the subdivided surface, so that the prior's rows hold their targets.
  for (int s = 0; s < scene.surface.size(); ++s) {
    scene.surface.input_offset.push_back(0.001 * std::cos(0.7 * s));
  }
  FrameEnergy energy(scene.surface, scene.cameras, scene.neighbourhoods, energy_options);
  ASSERT_GT(energy.pull_curvature().maxCoeff(), 0.0);
  ASSERT_FALSE(energy.regularizer().pairs().empty());
  SolverOptions options;
  options.max_iterations = 3;
  Eigen::VectorXd k = Eigen::VectorXd::Zero(energy.num_parameters());
  for (int s = 0; s < k.size(); ++s) k[s] = 0.002 * std::sin(1.3 * s);
  const double start = LeastSquaresCost(&energy, k);
  const SolverSummary summary = Solve(&energy, options, &k);
  ASSERT_GE(summary.trace.size(), 2u);
  // The trace holds -cost of Ceres' own problem: at the start and at the end.
  EXPECT_NEAR(-summary.trace.front().energy, start, 1e-12 * start);
  EXPECT_NEAR(-summary.trace.back().energy, summary.ls_cost_end, 1e-12 * start);
  EXPECT_LT(summary.ls_cost_end, start);
}

// Counts the preparations it is asked for.
class CountingTerm : public DataTerm {
 public:
  double Evaluate(const Eigen::VectorXd&, Eigen::VectorXd*) const override { return 0.0; }
  const std::vector<ResidualBlock>& residual_blocks() const override { return blocks_; }
  void PrepareResiduals(const Eigen::VectorXd&, bool with_jacobians) override {
    ++(with_jacobians ? with_jacobians_ : residuals_only_);
  }
  void BlockResiduals(int, double*, double*) const override {}
  int with_jacobians_ = 0, residuals_only_ = 0;

 private:
  std::vector<ResidualBlock> blocks_;
};

// Every new point is prepared once, with Jacobians, whether Ceres asks for its cost alone (a
// step's candidate) or for its Jacobians too, and whether or not it says the point is new.
TEST(CeresCostTest, TheCallbackPreparesEachPointOnce) {
  CountingTerm term;
  Eigen::VectorXd k = Eigen::VectorXd::Constant(3, 0.001);
  double seconds = 0.0;
  SharedEvaluationCallback callback({&term}, &k, &seconds);
  callback.PrepareForEvaluation(false, true);
  callback.PrepareForEvaluation(true, false);
  callback.PrepareForEvaluation(true, true);
  EXPECT_EQ(term.with_jacobians_, 1);
  EXPECT_EQ(term.residuals_only_, 0);
  k[1] = 0.002;
  callback.PrepareForEvaluation(false, true);
  EXPECT_EQ(term.with_jacobians_, 2);
  callback.PrepareForEvaluation(true, false);
  EXPECT_EQ(term.with_jacobians_, 2);
  EXPECT_EQ(term.residuals_only_, 0);
}

// The reduced block keeps what the solver's linear model is made of: the block's cost, its
// gradient J^T r and its Gauss-Newton matrix J^T J, for blocks of one parameter (consensus,
// surface_color) and of several (the paper's), with at most one residual more than parameters.
TEST_P(CeresCostTest, ReducedBlocksKeepCostGradientAndGaussNewtonMatrix) {
  const auto [similarity, overlap] = GetParam();
  CostScene scene(similarity, overlap);
  FrameEnergy& energy = scene.energy;
  const Eigen::VectorXd& k = scene.k;
  DataTerm& term = energy.data_term(0);
  // Prepared as in a solve; the full blocks then need the residuals: the paper's term, whose
  // blocks mix one parameter and several, has them from the callback too.
  Eigen::VectorXd point = k;
  double seconds = 0.0;
  SharedEvaluationCallback callback({&term}, &point, &seconds);
  callback.PrepareForEvaluation(true, true);
  if (similarity != "paper") term.PrepareResiduals(k, true);
  for (int b = 0; b < static_cast<int>(term.residual_blocks().size()); ++b) {
    const DataBlockCost full(term, b);
    const ReducedDataBlockCost reduced(term, term.block_summaries(), b);
    const int p = static_cast<int>(full.parameter_block_sizes().size());
    ASSERT_EQ(reduced.parameter_block_sizes().size(), static_cast<size_t>(p));
    EXPECT_EQ(reduced.num_residuals(), p == 1 ? 2 : std::min(full.num_residuals(), p + 1));

    // Evaluate both, with Jacobians and without; parameters are not read (the callback's).
    auto evaluate = [&](const ceres::CostFunction& cost, bool with_jacobians) {
      Eigen::VectorXd r(cost.num_residuals());
      Eigen::MatrixXd jacobian(cost.num_residuals(), p);
      std::vector<Eigen::VectorXd> columns(p, Eigen::VectorXd(cost.num_residuals()));
      std::vector<double*> jacobians;
      for (Eigen::VectorXd& column : columns) jacobians.push_back(column.data());
      std::vector<double> values(p, 0.0);
      std::vector<const double*> parameters;
      for (const double& value : values) parameters.push_back(&value);
      EXPECT_TRUE(
          cost.Evaluate(parameters.data(), r.data(), with_jacobians ? jacobians.data() : nullptr));
      for (int q = 0; q < p; ++q) jacobian.col(q) = columns[q];
      return std::make_pair(r, jacobian);
    };
    const auto [r, jacobian] = evaluate(full, true);
    const auto [r_reduced, jacobian_reduced] = evaluate(reduced, true);
    const auto [r_cost_only, unused] = evaluate(reduced, false);
    const double tolerance = 1e-9 * (1.0 + r.squaredNorm() + jacobian.squaredNorm());
    EXPECT_NEAR(r_reduced.squaredNorm(), r.squaredNorm(), tolerance) << "block " << b;
    EXPECT_NEAR(r_cost_only.squaredNorm(), r.squaredNorm(), tolerance) << "block " << b;
    EXPECT_LE((jacobian_reduced.transpose() * r_reduced - jacobian.transpose() * r).norm(),
              tolerance)
        << "block " << b;
    EXPECT_LE(
        (jacobian_reduced.transpose() * jacobian_reduced - jacobian.transpose() * jacobian).norm(),
        tolerance)
        << "block " << b;
  }
}

// A term's own block summaries (consensus computes them without storing its residuals) are those
// summed from its residuals and Jacobians.
TEST_P(CeresCostTest, BlockSummariesAreThoseOfTheResiduals) {
  const auto [similarity, overlap] = GetParam();
  CostScene scene(similarity, overlap);
  DataTerm& term = scene.energy.data_term(0);
  ASSERT_NE(term.block_summaries(), nullptr);
  // The general means (SummarisedDataTerm's), from the residuals and Jacobians.
  term.PrepareResiduals(scene.k, true);
  std::vector<BlockSummary> expected;
  const int num_blocks = static_cast<int>(term.residual_blocks().size());
  for (int b = 0; b < num_blocks; ++b) {
    const DataTerm::ResidualBlock& block = term.residual_blocks()[b];
    std::vector<double> r(block.num_residuals), jacobian(block.num_residuals);
    if (block.parameters.size() == 1) term.BlockResiduals(b, r.data(), jacobian.data());
    expected.push_back(
        SummarisedDataTerm::Summarise(r.data(), jacobian.data(), block.num_residuals));
  }
  term.block_summaries()->PrepareBlockSummaries(scene.k);
  int single = 0;
  for (int b = 0; b < num_blocks; ++b) {
    if (term.residual_blocks()[b].parameters.size() != 1) continue;
    ++single;
    const BlockSummary& summary = term.block_summaries()->BlockSummaryOf(b);
    const double tolerance = 1e-12 * (1.0 + expected[b].squared_norm + expected[b].curvature);
    EXPECT_NEAR(summary.squared_norm, expected[b].squared_norm, tolerance) << "block " << b;
    EXPECT_NEAR(summary.gradient, expected[b].gradient, tolerance) << "block " << b;
    EXPECT_NEAR(summary.curvature, expected[b].curvature, tolerance) << "block " << b;
  }
  if (similarity != "paper") {
    EXPECT_EQ(single, num_blocks);
  }
}

// With the secant curvature, a block of one parameter keeps its cost and gradient, models J^T J
// until it has been evaluated at two points, then the secant of its gradient between them, held
// within the bounds and never below g^2 / |r|^2.
TEST_P(CeresCostTest, SecantBlocksKeepCostAndGradientAndModelTheSecant) {
  const auto [similarity, overlap] = GetParam();
  CostScene scene(similarity, overlap);
  DataTerm& term = scene.energy.data_term(0);
  const int num_blocks = static_cast<int>(term.residual_blocks().size());
  std::vector<std::unique_ptr<ReducedDataBlockCost>> costs;
  for (int b = 0; b < num_blocks; ++b) {
    costs.push_back(std::make_unique<ReducedDataBlockCost>(term, term.block_summaries(), b, true));
  }
  // Block b's residuals and its Jacobian's one entry at k, with k_s taken from k.
  auto evaluate = [&](int b, const Eigen::VectorXd& k, Eigen::Vector2d* r) {
    const double value = k[term.residual_blocks()[b].parameters[0]];
    const double* parameters[] = {&value};
    double jacobian[2];
    double* jacobians[] = {jacobian};
    EXPECT_TRUE(costs[b]->Evaluate(parameters, r->data(), jacobians));
    EXPECT_EQ(jacobian[1], 0.0);
    return jacobian[0];
  };
  term.block_summaries()->PrepareBlockSummaries(scene.k);
  std::vector<double> first_gradient(num_blocks);
  int single = 0, lowered = 0, raised = 0;
  for (int b = 0; b < num_blocks; ++b) {
    if (term.residual_blocks()[b].parameters.size() != 1) continue;
    ++single;
    Eigen::Vector2d r;
    const double length = evaluate(b, scene.k, &r);
    EXPECT_NEAR(length * length, term.block_summaries()->BlockSummaryOf(b).curvature,
                1e-12 * (1.0 + term.block_summaries()->BlockSummaryOf(b).curvature))
        << "block " << b;
    first_gradient[b] = term.block_summaries()->BlockSummaryOf(b).gradient;
  }
  if (single == 0) return;
  const double step = 0.0003;
  const Eigen::VectorXd moved = scene.k.array() + step;
  term.block_summaries()->PrepareBlockSummaries(moved);
  for (int b = 0; b < num_blocks; ++b) {
    if (term.residual_blocks()[b].parameters.size() != 1) continue;
    const BlockSummary& summary = term.block_summaries()->BlockSummaryOf(b);
    Eigen::Vector2d r;
    const double length = evaluate(b, moved, &r);
    const double tolerance = 1e-9 * (1.0 + summary.squared_norm + summary.curvature);
    EXPECT_NEAR(r.squaredNorm(), summary.squared_norm, tolerance) << "block " << b;
    EXPECT_NEAR(length * r[0], summary.gradient, tolerance) << "block " << b;
    const double secant = (summary.gradient - first_gradient[b]) / step;
    double expected = std::clamp(secant, ReducedDataBlockCost::kMinSecantFactor * summary.curvature,
                                 ReducedDataBlockCost::kMaxSecantFactor * summary.curvature);
    if (summary.squared_norm > 0.0) {
      expected = std::max(expected, summary.gradient * summary.gradient / summary.squared_norm);
    }
    EXPECT_NEAR(length * length, expected, 1e-6 * (1.0 + summary.curvature)) << "block " << b;
    lowered += length * length < 0.999 * summary.curvature;
    raised += length * length > 1.001 * summary.curvature;
  }
  // The scene's blocks are curved both ways: the secant is not J^T J.
  EXPECT_GT(lowered + raised, 0);
}

// A similarity that says it is a least-squares term is one: its E is minus half the sum of
// squares of its residuals, which lets the solvers take E from the least-squares cost.
TEST_P(CeresCostTest, LeastSquaresTermsAgreeWithTheirResiduals) {
  const auto [similarity, overlap] = GetParam();
  CostScene scene(similarity, overlap);
  FrameEnergy& energy = scene.energy;
  const Eigen::VectorXd& k = scene.k;
  DataTerm& term = energy.data_term(0);
  EXPECT_EQ(term.IsLeastSquares(), similarity != "paper");
  if (!term.IsLeastSquares()) return;
  double e = 0.0, cost = 0.0;
  EvaluateEnergyAndCost(&energy, k, &e, &cost);
  EXPECT_NEAR(e, energy.Evaluate(k, nullptr), 1e-12 * (1.0 + std::abs(e)));
  EXPECT_NEAR(cost, -e, 1e-12 * (1.0 + std::abs(e)));
}

// A term of one block with fixed residuals and Jacobian, for the reduction of a block of several
// parameters (QR), which no similarity of the product needs today.
class FixedBlockTerm : public DataTerm {
 public:
  FixedBlockTerm(Eigen::VectorXd r, Eigen::MatrixXd jacobian)
      : r_(std::move(r)), jacobian_(std::move(jacobian)) {
    ResidualBlock block;
    for (int q = 0; q < jacobian_.cols(); ++q) block.parameters.push_back(q);
    block.num_residuals = static_cast<int>(r_.size());
    blocks_.push_back(block);
  }
  double Evaluate(const Eigen::VectorXd&, Eigen::VectorXd*) const override { return 0.0; }
  const std::vector<ResidualBlock>& residual_blocks() const override { return blocks_; }
  void PrepareResiduals(const Eigen::VectorXd&, bool) override {}
  void BlockResiduals(int, double* residuals, double* jacobian) const override {
    std::copy_n(r_.data(), r_.size(), residuals);
    if (jacobian == nullptr) return;
    const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> row_major =
        jacobian_;
    std::copy_n(row_major.data(), row_major.size(), jacobian);
  }

 private:
  Eigen::VectorXd r_;
  Eigen::MatrixXd jacobian_;
  std::vector<ResidualBlock> blocks_;
};

TEST(CeresCostTest, AReducedBlockOfSeveralParametersKeepsTheLinearModel) {
  std::srand(7);
  const FixedBlockTerm term(Eigen::VectorXd::Random(12), Eigen::MatrixXd::Random(12, 3));
  const ReducedDataBlockCost reduced(term, nullptr, 0);
  ASSERT_EQ(reduced.num_residuals(), 4);
  Eigen::VectorXd r(4);
  std::vector<Eigen::VectorXd> columns(3, Eigen::VectorXd(4));
  std::vector<double*> jacobians = {columns[0].data(), columns[1].data(), columns[2].data()};
  const double zero = 0.0;
  const std::vector<const double*> parameters(3, &zero);
  ASSERT_TRUE(reduced.Evaluate(parameters.data(), r.data(), jacobians.data()));
  Eigen::MatrixXd jacobian(4, 3);
  for (int q = 0; q < 3; ++q) jacobian.col(q) = columns[q];
  Eigen::VectorXd full_r(12);
  Eigen::Matrix<double, 12, 3, Eigen::RowMajor> full_jacobian;
  term.BlockResiduals(0, full_r.data(), full_jacobian.data());
  // The linear model |r + J dk|^2 agrees at any step dk.
  for (const Eigen::Vector3d& dk : {Eigen::Vector3d(0.3, -1.0, 2.0), Eigen::Vector3d(-5, 0.1, 0)}) {
    EXPECT_NEAR((r + jacobian * dk).squaredNorm(), (full_r + full_jacobian * dk).squaredNorm(),
                1e-9);
  }
}

class SolverTest : public ::testing::TestWithParam<std::string> {};

// Every solver raises the energy from the start, keeps |k| <= k_max, and reports statistics
// that agree with the energy it returns.
TEST_P(SolverTest, ImprovesTheEnergyWithinBounds) {
  EnergyScene scene = MakeEnergyScene({0.0, 0.5, -0.5}, 3, 13);
  FrameEnergy energy(scene.surface, scene.cameras, scene.neighbourhoods,
                     Options("surface_color", "printed"));
  SolverOptions options;
  ASSERT_TRUE(StringToEnum(std::string(GetParam()), &options.type));
  options.max_iterations = 30;
  Eigen::VectorXd k = Eigen::VectorXd::Constant(energy.num_parameters(), 0.004);
  const SolverSummary summary = Solve(&energy, options, &k);
  EXPECT_EQ(summary.solver, GetParam());
  EXPECT_GT(summary.energy_end, summary.energy_start);
  EXPECT_LT(summary.ls_cost_end, summary.ls_cost_start);
  // To rounding: for a least-squares similarity E is taken from the cost, summed otherwise.
  EXPECT_NEAR(summary.energy_end, energy.Evaluate(k, nullptr),
              1e-12 * std::abs(summary.energy_end));
  EXPECT_LE(k.cwiseAbs().maxCoeff(), energy.options().k_max + 1e-12);
  EXPECT_GT(summary.iterations, 0);
  EXPECT_FALSE(summary.trace.empty());
}

// Ceres' dogleg takes exact Gauss-Newton steps: with conjugate gradients the options are refused
// before any solve, instead of a solve that stops at once.
TEST(SolverOptionsTest, DoglegNeedsAnExactLinearSolver) {
  SolverOptions options;
  options.trust_region = TrustRegionType::kDogleg;
  options.linear_solver = LinearSolverType::kCgnr;
  EXPECT_THROW(options.Check(), Error);
  options.linear_solver = LinearSolverType::kSparseNormalCholesky;
  EXPECT_NO_THROW(options.Check());
  options.linear_solver = LinearSolverType::kCgnr;
  options.type = SolverType::kGradientAscent;  // No trust region there: nothing to refuse.
  EXPECT_NO_THROW(options.Check());
}

INSTANTIATE_TEST_SUITE_P(AllSolvers, SolverTest,
                         ::testing::Values("ceres", "gradient_ascent", "lbfgs"));

// For the colour similarity the least-squares cost is exactly -E: Ceres and L-BFGS, which
// optimise the two forms, must agree on the optimum.
TEST(SolverTest, CeresAndLbfgsReachTheSameOptimum) {
  EnergyScene scene = MakeEnergyScene({0.0, 0.6, -0.6}, 3, 23);
  FrameEnergy energy(scene.surface, scene.cameras, scene.neighbourhoods,
                     Options("surface_color", "printed"));
  SolverOptions options;
  options.max_iterations = 200;
  options.function_tolerance = 1e-12;
  Eigen::VectorXd k_ceres = Eigen::VectorXd::Zero(energy.num_parameters());
  Eigen::VectorXd k_lbfgs = k_ceres;
  options.type = SolverType::kCeres;
  const SolverSummary ceres = Solve(&energy, options, &k_ceres);
  options.type = SolverType::kLbfgs;
  const SolverSummary lbfgs = Solve(&energy, options, &k_lbfgs);
  EXPECT_NEAR(ceres.ls_cost_end, -ceres.energy_end, 1e-12 * std::abs(ceres.energy_end));
  EXPECT_NEAR(ceres.energy_end, lbfgs.energy_end, 1e-6 * std::abs(ceres.energy_end));
  EXPECT_LT((k_ceres - k_lbfgs).cwiseAbs().maxCoeff(), 1e-4);
}

// Steps far too long for the energy overshoot every time; the ascent must still not return a k
// below where it started.
TEST(SolverTest, GradientAscentReturnsItsBestIterate) {
  EnergyScene scene = MakeEnergyScene({0.0, 0.5}, 3, 41);
  FrameEnergy energy(scene.surface, scene.cameras, scene.neighbourhoods,
                     Options("surface_color", "printed"));
  SolverOptions options;
  options.type = SolverType::kGradientAscent;
  options.initial_step = 0.01;
  options.max_step = 0.01;
  options.step_shrink = 0.99;
  options.max_iterations = 5;
  Eigen::VectorXd k = Eigen::VectorXd::Zero(energy.num_parameters());
  const SolverSummary summary = Solve(&energy, options, &k);
  double lowest = summary.trace.front().energy;
  for (const SolverIteration& row : summary.trace) lowest = std::min(lowest, row.energy);
  ASSERT_LT(lowest, summary.energy_start) << "the overshoot this test needs did not happen";
  EXPECT_GE(summary.energy_end, summary.energy_start);
  EXPECT_NE(summary.termination.find("best iterate"), std::string::npos) << summary.termination;
}

}  // namespace
}  // namespace finecap
