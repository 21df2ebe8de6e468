#include "finecap/solvers/sweep.h"

#include <cmath>

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
  const Eigen::VectorXd k = SweepInitialization(&energy, SweepOptions());
  ASSERT_EQ(k.size(), energy.num_parameters());
  EXPECT_TRUE(k.isZero(0.0)) << k.transpose();
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

TEST(SweepTest, SweepOffStartsEveryGaussianAtZero) {
  const EnergyScene scene = MakeEnergyScene({0.0, 0.6}, 2, 3);
  FrameEnergy energy(scene.surface, scene.cameras, scene.neighbourhoods,
                     SweepEnergyOptions(SimilarityType::kConsensus));
  SweepOptions sweep;
  sweep.samples = 0;
  EXPECT_TRUE(SweepInitialization(&energy, sweep).isZero(0.0));
}

}  // namespace
}  // namespace finecap
