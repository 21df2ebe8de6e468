#include "finecap/solvers/sweep.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "energy_fixture.h"
#include "finecap/energy/frame_energy.h"

namespace finecap {
namespace {

EnergyOptions SweepEnergyOptions(SimilarityType similarity) {
  EnergyOptions options;
  options.similarity = similarity;
  options.k_max = 0.01;
  return options;
}

// The consensus similarity compares cameras with each other: with one camera it has no residual
// block, so no Gaussian has a cost curve and every one starts on the coarse mesh, not at -k_max.
TEST(SweepTest, GaussiansNoBlockReachesStartOnTheCoarseMesh) {
  const EnergyScene scene = MakeEnergyScene({0.3}, 2, 7);
  FrameEnergy energy(scene.surface, scene.cameras, scene.neighbourhoods,
                     SweepEnergyOptions(SimilarityType::kConsensus));
  ASSERT_TRUE(energy.data_term(0).residual_blocks().empty());
  const SweepResult result = Sweep(&energy, SweepOptions());
  ASSERT_EQ(result.k.size(), energy.num_parameters());
  EXPECT_TRUE(result.k.isZero(0.0)) << result.k.transpose();
  // No curve is counted, and nothing says that the range is too wide.
  EXPECT_EQ(result.reach, std::numeric_limits<double>::infinity());
}

// With cameras to compare, each start is a sampled displacement moved by at most half a sample
// towards the vertex of the parabola through its neighbours (the best sample is the lowest of
// the three), so it stays inside [-k_max, k_max].
TEST(SweepTest, StartsLieWithinTheSweptRange) {
  const EnergyScene scene = MakeEnergyScene({0.0, 0.6, -0.4}, 2, 3);
  for (const SimilarityType similarity : {SimilarityType::kPaper, SimilarityType::kConsensus}) {
    const EnergyOptions options = SweepEnergyOptions(similarity);
    FrameEnergy energy(scene.surface, scene.cameras, scene.neighbourhoods, options);
    ASSERT_FALSE(energy.data_term(0).residual_blocks().empty());
    SweepOptions sweep;
    sweep.samples = 9;
    const Eigen::VectorXd k = SweepInitialization(&energy, sweep);
    const double step = 2.0 * options.k_max / (sweep.samples - 1);
    for (int s = 0; s < k.size(); ++s) {
      const double from_sample =
          k[s] + options.k_max - step * std::round((k[s] + options.k_max) / step);
      EXPECT_LE(std::abs(from_sample), 0.5 * step + 1e-15) << "Gaussian " << s;
    }
    EXPECT_LE(k.cwiseAbs().maxCoeff(), options.k_max);
    EXPECT_GT(k.cwiseAbs().maxCoeff(), 0.0) << "every start on the coarse mesh";
  }
}

// Displacements -8 .. 8 (17 samples) and a window of 2 each side of 0.
Eigen::VectorXd Displacements() { return Eigen::VectorXd::LinSpaced(17, -8.0, 8.0); }

// A cost that falls all the way to the upper end of the window and on beyond it: the window
// widens until the minimum (at 6) lies inside it.
TEST(WindowedMinimumTest, ACostFallingBeyondTheWindowWidensIt) {
  const Eigen::VectorXd k = Displacements();
  const Eigen::RowVectorXd costs = (k.array() - 6.0).square().matrix().transpose();
  EXPECT_DOUBLE_EQ(k[WindowedMinimum(costs, k, 2.0)], 6.0);
}

// A minimum inside the window (at -1) is kept although a deeper one lies outside it (at 6).
TEST(WindowedMinimumTest, AMinimumInsideTheWindowIsKept) {
  const Eigen::VectorXd k = Displacements();
  const Eigen::RowVectorXd costs =
      (-Eigen::exp(-(k.array() + 1.0).square()) - 2.0 * Eigen::exp(-(k.array() - 6.0).square()))
          .matrix()
          .transpose();
  EXPECT_DOUBLE_EQ(k[WindowedMinimum(costs, k, 2.0)], -1.0);
  // The whole range at once takes the deeper one.
  EXPECT_DOUBLE_EQ(k[WindowedMinimum(costs, k, 8.0)], 6.0);
}

// The lowest cost at the window's end, but higher beyond it: the window stays, and the start is
// its end.
TEST(WindowedMinimumTest, AnEndLowerThanWhatLiesBeyondIsKept) {
  const Eigen::VectorXd k = Displacements();
  Eigen::RowVectorXd costs = (k.array() - 2.0).square().matrix().transpose();
  costs.tail(5).setConstant(0.5);  // 4 .. 8: above the cost at 2 (0), beyond the window.
  EXPECT_DOUBLE_EQ(k[WindowedMinimum(costs, k, 2.0)], 2.0);
}

// A cost that keeps falling to the end of the range stops there, whatever the window.
TEST(WindowedMinimumTest, ACostFallingToTheRangesEndStopsThere) {
  const Eigen::VectorXd k = Displacements();
  const Eigen::RowVectorXd costs = (-k.array()).matrix().transpose();
  EXPECT_EQ(WindowedMinimum(costs, k, 2.0), 16);
  EXPECT_EQ(WindowedMinimum((-costs).eval(), k, 0.5), 0);
}

// The window's half-width at the end of the search: the first window, or the one it doubled to.
TEST(WindowedMinimumTest, TellsTheWindowItSearched) {
  const Eigen::VectorXd k = Displacements();
  double searched = 0.0;
  WindowedMinimum((k.array() - 1.0).square().matrix().transpose(), k, 2.0, &searched);
  EXPECT_DOUBLE_EQ(searched, 2.0);
  WindowedMinimum((k.array() - 6.0).square().matrix().transpose(), k, 2.0, &searched);
  EXPECT_DOUBLE_EQ(searched, 8.0);
}

// Two minima of a pattern that matches itself, at -4 and 4: as deep, neither stands out; the
// other one shallower by half the curve's median height, half; much shallower, 1.
TEST(CostUniquenessTest, ARivalMinimumAsDeepLeavesNoUniqueness) {
  const Eigen::VectorXd k = Displacements();
  const auto curve = [&](double rival_depth) -> Eigen::RowVectorXd {
    return (1.0 - Eigen::exp(-(k.array() + 4.0).square()) -
            rival_depth * Eigen::exp(-(k.array() - 4.0).square()))
        .matrix()
        .transpose();
  };
  const int chosen = 4;  // k = -4.
  EXPECT_NEAR(CostUniqueness(curve(1.0), k, chosen, 2.0, 8.0), 0.0, 1e-12);
  // The curve's median is about 1 (most samples lie far from both minima), its own cost 0.
  EXPECT_NEAR(CostUniqueness(curve(0.5), k, chosen, 2.0, 8.0), 0.5, 0.01);
  EXPECT_GT(CostUniqueness(curve(0.0), k, chosen, 2.0, 8.0), 0.99);
}

// A rival outside the window the start was searched in does not count (the windowed search keeps
// a nearer minimum on purpose), nor one closer than `distinct` (the same minimum's flanks); with
// nothing left to compare, the start is unique.
TEST(CostUniquenessTest, OnlyDistinctRivalsInsideTheSearchedWindowCount) {
  const Eigen::VectorXd k = Displacements();
  const Eigen::RowVectorXd costs =
      (1.0 - Eigen::exp(-(k.array() + 1.0).square()) - Eigen::exp(-(k.array() - 6.0).square()))
          .matrix()
          .transpose();
  const int chosen = 7;  // k = -1.
  EXPECT_NEAR(CostUniqueness(costs, k, chosen, 2.0, 8.0), 0.0, 1e-12);
  EXPECT_GT(CostUniqueness(costs, k, chosen, 2.0, 4.0), 0.9);
  EXPECT_DOUBLE_EQ(CostUniqueness(costs, k, chosen, 20.0, 8.0), 1.0);
}

// A curve flat at its lowest over half its samples or more says nothing of where the surface is.
TEST(CostUniquenessTest, ACurveLowOverHalfItsSamplesIsAmbiguous) {
  const Eigen::VectorXd k = Displacements();
  Eigen::RowVectorXd costs = Eigen::RowVectorXd::Zero(k.size());
  costs.head(5).setConstant(1.0);
  EXPECT_DOUBLE_EQ(CostUniqueness(costs, k, 10, 2.0, 8.0), 0.0);
}

// Every Gaussian gets a uniqueness in [0, 1], those without a cost curve 1.
TEST(SweepTest, UniquenessLiesBetweenZeroAndOne) {
  const EnergyScene scene = MakeEnergyScene({0.0, 0.6, -0.4}, 2, 3);
  FrameEnergy energy(scene.surface, scene.cameras, scene.neighbourhoods,
                     SweepEnergyOptions(SimilarityType::kConsensus));
  const SweepResult result = Sweep(&energy, SweepOptions());
  ASSERT_EQ(result.uniqueness.size(), energy.num_parameters());
  EXPECT_GE(result.uniqueness.minCoeff(), 0.0);
  EXPECT_LE(result.uniqueness.maxCoeff(), 1.0);
  const EnergyScene lone = MakeEnergyScene({0.3}, 2, 7);  // One camera: no cost curve at all.
  FrameEnergy lone_energy(lone.surface, lone.cameras, lone.neighbourhoods,
                          SweepEnergyOptions(SimilarityType::kConsensus));
  EXPECT_TRUE(Sweep(&lone_energy, SweepOptions()).uniqueness.isOnes(0.0));
}

// The share of Gaussians the range limits counts those whose start is at an end of the range:
// with the range so narrow that the costs cannot turn (one sample each side of 0 and the input
// off by more), some are; with a wide range fewer. The sweep's reach, which says whether a range
// is wider than its Gaussians need, lies within the range, and all of it with no share left out.
TEST(SweepTest, ANarrowRangeLimitsMoreGaussians) {
  const EnergyScene scene = MakeEnergyScene({0.0, 0.6, -0.4}, 2, 3);
  SweepOptions sweep;
  sweep.samples = 9;
  sweep.max_step_sigmas = 0.0;
  double share[2];
  for (int wide = 0; wide < 2; ++wide) {
    EnergyOptions options = SweepEnergyOptions(SimilarityType::kConsensus);
    options.k_max = wide ? 0.01 : 1e-4;
    FrameEnergy energy(scene.surface, scene.cameras, scene.neighbourhoods, options);
    const SweepResult result = Sweep(&energy, sweep);
    int at_ends = 0;
    for (int s = 0; s < result.k.size(); ++s) at_ends += std::abs(result.k[s]) == options.k_max;
    EXPECT_DOUBLE_EQ(result.share_at_ends, static_cast<double>(at_ends) / result.k.size());
    share[wide] = result.share_at_ends;
    EXPECT_LE(result.reach, options.k_max);
    sweep.narrow_share = 0.0;
    EXPECT_DOUBLE_EQ(Sweep(&energy, sweep).reach, result.k.cwiseAbs().maxCoeff());
    sweep.narrow_share = SweepOptions().narrow_share;
  }
  EXPECT_GT(share[0], share[1]);
}

TEST(SweepTest, SweepOffStartsEveryGaussianAtZero) {
  const EnergyScene scene = MakeEnergyScene({0.0, 0.6}, 2, 3);
  FrameEnergy energy(scene.surface, scene.cameras, scene.neighbourhoods,
                     SweepEnergyOptions(SimilarityType::kConsensus));
  SweepOptions sweep;
  sweep.samples = 0;
  EXPECT_TRUE(SweepInitialization(&energy, sweep).isZero(0.0));
}

// Around k = 0 over the whole range, with the plane sweep's samples, smoothing and no window, the
// detail stage's sweep is the plane sweep: the same costs (each term's block costs at uniform
// displacements), the same choice.
TEST(SweepAroundTest, AroundTheInputOverTheWholeRangeIsThePlaneSweep) {
  const EnergyScene scene = MakeEnergyScene({0.0, 0.6, -0.4}, 2, 3);
  const EnergyOptions options = SweepEnergyOptions(SimilarityType::kConsensus);
  FrameEnergy energy(scene.surface, scene.cameras, scene.neighbourhoods, options);
  SweepOptions sweep;
  sweep.samples = 9;
  sweep.max_step_sigmas = 0.0;
  sweep.window_sigmas = 0.0;
  sweep.smoothing_rounds = 2;
  const Eigen::VectorXd planes = SweepInitialization(&energy, sweep);
  const Eigen::VectorXd around =
      SweepAround(&energy, Eigen::VectorXd::Zero(energy.num_parameters()), options.k_max,
                  2.0 * options.k_max / (sweep.samples - 1), sweep.smoothing_rounds);
  EXPECT_GT(planes.cwiseAbs().maxCoeff(), 0.0);
  EXPECT_TRUE(around.isApprox(planes, 1e-12)) << around.transpose() << "\n" << planes.transpose();
}

// Each Gaussian moves from its own start by at most the range and half a step (the parabola's
// vertex lies within half a step of the lowest sample), and a Gaussian with no cost curve (one
// camera: the consensus has no block) stays where it starts.
TEST(SweepAroundTest, EachGaussianMovesFromItsStartByAtMostTheRange) {
  const EnergyOptions options = SweepEnergyOptions(SimilarityType::kConsensus);
  const double range = 0.002, step = 0.0005;
  for (const int cameras : {1, 3}) {
    const std::vector<double> tilts =
        cameras == 1 ? std::vector<double>{0.3} : std::vector<double>{0.0, 0.6, -0.4};
    const EnergyScene scene = MakeEnergyScene(tilts, 2, 5);
    FrameEnergy energy(scene.surface, scene.cameras, scene.neighbourhoods, options);
    const int n = energy.num_parameters();
    const Eigen::VectorXd start = 0.004 * Eigen::VectorXd::LinSpaced(n, -1.0, 1.0);
    const Eigen::VectorXd moved = SweepAround(&energy, start, range, step, 1);
    ASSERT_EQ(moved.size(), n);
    const double largest = (moved - start).cwiseAbs().maxCoeff();
    if (cameras == 1) {
      EXPECT_EQ(largest, 0.0);
    } else {
      EXPECT_GT(largest, 0.0);
      EXPECT_LE(largest, range + 0.5 * step + 1e-15);
    }
  }
}

}  // namespace
}  // namespace finecap
