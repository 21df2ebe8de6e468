#include "finecap/measure/metrics.h"

#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "finecap/util/error.h"
#include "test_util.h"

namespace finecap {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
using testing_util::ExpectErrorMentions;

Eigen::VectorXd Vector(const std::vector<double>& values) {
  return Eigen::Map<const Eigen::VectorXd>(values.data(), static_cast<Eigen::Index>(values.size()));
}

TEST(MetricsPercentile, InterpolatesBetweenOrderStatistics) {
  // Sorted: 1 2 3 4 5; rank of the 95th percentile is 0.95 * 4 = 3.8 -> 4 + 0.8 * (5 - 4).
  EXPECT_DOUBLE_EQ(Percentile({5, 1, 4, 2, 3}, 95.0), 4.8);
  EXPECT_DOUBLE_EQ(Percentile({5, 1, 4, 2, 3}, 50.0), 3.0);
  EXPECT_DOUBLE_EQ(Percentile({5, 1, 4, 2, 3}, 0.0), 1.0);
  EXPECT_DOUBLE_EQ(Percentile({5, 1, 4, 2, 3}, 100.0), 5.0);
  // Rank 0.25 * 3 = 0.75 between 10 and 20.
  EXPECT_DOUBLE_EQ(Percentile({40, 10, 30, 20}, 25.0), 17.5);
  EXPECT_DOUBLE_EQ(Percentile({7}, 95.0), 7.0);
}

TEST(MetricsPercentile, IgnoresNonFiniteAndReportsNoDataAsNaN) {
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_DOUBLE_EQ(Percentile({kNaN, 2, inf, 1, kNaN, 3}, 50.0), 2.0);
  EXPECT_TRUE(std::isnan(Percentile({}, 50.0)));
  EXPECT_TRUE(std::isnan(Percentile({kNaN, kNaN}, 50.0)));
}

TEST(MetricsPercentile, RejectsPercentOutsideRange) {
  ExpectErrorMentions([] { Percentile({1, 2}, 101.0); }, {"percentile", "outside [0, 100]"});
  ExpectErrorMentions([] { Percentile({1, 2}, -1.0); }, {"percentile"});
}

TEST(MetricsErrorStats, MatchesHandComputedValuesAndSkipsNaN) {
  // Errors: -3, 4, (NaN skipped), 0, (NaN truth skipped), 1 -> |e| = 3 4 0 1.
  const Eigen::VectorXd estimate = Vector({0, 5, kNaN, 2, 1, 3});
  const Eigen::VectorXd truth = Vector({3, 1, 0, 2, kNaN, 2});
  const ErrorStats stats = ComputeErrorStats(estimate, truth);
  EXPECT_EQ(stats.count, 4);
  EXPECT_DOUBLE_EQ(stats.rms, std::sqrt((9.0 + 16.0 + 0.0 + 1.0) / 4.0));
  EXPECT_DOUBLE_EQ(stats.mean_abs, 2.0);
  EXPECT_DOUBLE_EQ(stats.max_abs, 4.0);
  // Sorted |e|: 0 1 3 4; rank 0.95 * 3 = 2.85 -> 3 + 0.85 * 1.
  EXPECT_DOUBLE_EQ(stats.p95_abs, 3.85);
}

TEST(MetricsErrorStats, RegionUsesOnlyItsIndices) {
  const Eigen::VectorXd estimate = Vector({1, 2, 3, 4});
  const Eigen::VectorXd truth = Vector({1, 0, 3, 10});
  const ErrorStats textured = ComputeErrorStats(estimate, truth, {1, 2});
  EXPECT_EQ(textured.count, 2);
  EXPECT_DOUBLE_EQ(textured.rms, std::sqrt(4.0 / 2.0));
  EXPECT_DOUBLE_EQ(textured.mean_abs, 1.0);
  EXPECT_DOUBLE_EQ(textured.max_abs, 2.0);
  const ErrorStats textureless = ComputeErrorStats(estimate, truth, {3});
  EXPECT_DOUBLE_EQ(textureless.rms, 6.0);
  EXPECT_DOUBLE_EQ(textureless.p95_abs, 6.0);
}

TEST(MetricsErrorStats, EmptyRegionGivesNoDataNotZero) {
  const Eigen::VectorXd values = Vector({1, 2});
  for (const ErrorStats& stats :
       {ComputeErrorStats(values, values, {}), ComputeErrorStats(Vector({kNaN}), Vector({1})),
        ComputeErrorStats(Eigen::VectorXd(), Eigen::VectorXd())}) {
    EXPECT_TRUE(stats.empty());
    EXPECT_EQ(stats.count, 0);
    EXPECT_TRUE(std::isnan(stats.rms));
    EXPECT_TRUE(std::isnan(stats.mean_abs));
    EXPECT_TRUE(std::isnan(stats.p95_abs));
    EXPECT_TRUE(std::isnan(stats.max_abs));
  }
}

TEST(MetricsErrorStats, RejectsMismatchedSizesAndIndicesOutOfRange) {
  ExpectErrorMentions(
      [] {
        ComputeErrorStats(Vector({1, 2}), Vector({1}));
      },
      {"different sizes", "2 and 1"});
  ExpectErrorMentions(
      [] {
        ComputeErrorStats(Vector({1, 2}), Vector({1, 2}), {0, 2});
      },
      {"region index 2", "[0, 2)"});
  ExpectErrorMentions(
      [] {
        ComputeErrorStats(Vector({1, 2}), Vector({1, 2}), {-1});
      },
      {"region index -1"});
}

TEST(MetricsDetailRecovered, IsTheShareOfCoarseErrorRemoved) {
  EXPECT_DOUBLE_EQ(DetailRecovered(0.25, 1.0), 0.75);
  EXPECT_DOUBLE_EQ(DetailRecovered(0.0, 2.0), 1.0);
  EXPECT_DOUBLE_EQ(DetailRecovered(3.0, 2.0), -0.5);
  EXPECT_TRUE(std::isnan(DetailRecovered(0.1, 0.0)));
  EXPECT_TRUE(std::isnan(DetailRecovered(0.1, kNaN)));
}

TEST(MetricsAngularError, AveragesAnglesInDegreesAndSkipsUnusablePairs) {
  Eigen::Matrix3Xd estimate(3, 5), truth(3, 5);
  // 0 degrees, 90 degrees, 60 degrees (unnormalised input), zero vector, NaN.
  estimate.col(0) << 0, 0, 1;
  truth.col(0) << 0, 0, 1;
  estimate.col(1) << 1, 0, 0;
  truth.col(1) << 0, 1, 0;
  estimate.col(2) << 2, 0, 0;
  truth.col(2) << 0.5, std::sqrt(3.0) / 2.0, 0;
  estimate.col(3) << 0, 0, 0;
  truth.col(3) << 1, 0, 0;
  estimate.col(4) << kNaN, 0, 0;
  truth.col(4) << 1, 0, 0;
  EXPECT_NEAR(MeanAngularErrorDegrees(estimate, truth), (0.0 + 90.0 + 60.0) / 3.0, 1e-12);
}

TEST(MetricsAngularError, KeepsTinyAnglesAccurateAndHandlesOpposites) {
  Eigen::Matrix3Xd estimate(3, 1), truth(3, 1);
  const double angle = 1e-7;  // radians; acos(cos(1e-7)) would round to 0.
  estimate.col(0) << std::cos(angle), std::sin(angle), 0;
  truth.col(0) << 1, 0, 0;
  EXPECT_NEAR(MeanAngularErrorDegrees(estimate, truth), angle * 180.0 / M_PI, 1e-15);
  truth.col(0) << -std::cos(angle), -std::sin(angle), 0;
  EXPECT_NEAR(MeanAngularErrorDegrees(estimate, truth), 180.0, 1e-9);
}

TEST(MetricsAngularError, NoUsablePairGivesNaNAndSizeMismatchThrows) {
  EXPECT_TRUE(std::isnan(MeanAngularErrorDegrees(Eigen::Matrix3Xd(3, 0), Eigen::Matrix3Xd(3, 0))));
  ExpectErrorMentions(
      [] { MeanAngularErrorDegrees(Eigen::Matrix3Xd::Zero(3, 2), Eigen::Matrix3Xd::Zero(3, 1)); },
      {"normal sets", "different sizes"});
}

// A steady error, however large, does not flicker; one that swaps sign every frame, +e then -e,
// changes by 2e.
TEST(MetricsFlicker, IsTheRmsChangeOfTheSignedErrorFromOneFrameToTheNext) {
  const std::vector<int> all = {0, 1, 2};
  const Eigen::VectorXd offset = Vector({0.3, 0.3, 0.3});
  EXPECT_EQ(ComputeFlicker(offset, offset, all).rms, 0.0);
  EXPECT_EQ(ComputeFlicker(offset, offset, all).count, 3);
  const double e = 0.25;
  EXPECT_DOUBLE_EQ(ComputeFlicker(Vector({e, -e, e}), Vector({-e, e, -e}), all).rms, 2 * e);
  // Changes 0, 3 and 4: RMS sqrt(25 / 3); a vertex unknown in either frame does not count.
  EXPECT_DOUBLE_EQ(ComputeFlicker(Vector({1, 1, -2}), Vector({1, 4, 2}), all).rms,
                   std::sqrt(25.0 / 3.0));
  const ErrorStats partial = ComputeFlicker(Vector({kNaN, 1, -2}), Vector({1, 4, kNaN}), all);
  EXPECT_EQ(partial.count, 1);
  EXPECT_DOUBLE_EQ(partial.rms, 3.0);
  EXPECT_TRUE(ComputeFlicker(Vector({kNaN}), Vector({1}), {0}).empty());
}

TEST(MetricsFlicker, SignedErrorsAreKnownWhereTheRefinementGaveAValue) {
  const SignedErrors errors =
      SignedErrorsOf(Vector({0.5, kNaN, 0.0}), Vector({0.25, 1.0, kNaN}), Vector({2, 3, 4}));
  EXPECT_DOUBLE_EQ(errors.refined[0], 0.25);
  EXPECT_TRUE(std::isnan(errors.refined[1]) && std::isnan(errors.refined[2]));
  EXPECT_DOUBLE_EQ(errors.subdivided[0], -0.25);
  EXPECT_TRUE(std::isnan(errors.subdivided[1]));  // Not refined.
  EXPECT_DOUBLE_EQ(errors.coarse[0], -2.0);
  EXPECT_TRUE(std::isnan(errors.coarse[1]));
  EXPECT_DOUBLE_EQ(errors.coarse[2], -4.0);
  ExpectErrorMentions(
      [] {
        SignedErrorsOf(Vector({0}), Vector({0, 0}), Vector({0}));
      },
      {"different sizes"});
}

// Each surface against its own error in the frame before; no frame before, no flicker.
TEST(MetricsFlicker, OfEachSurfaceAgainstTheFrameBefore) {
  const std::vector<int> all = {0, 1};
  // The truth moves by 1 and 3 mm; the refinement follows it to within a steady 0.5 mm.
  const SignedErrors before = SignedErrorsOf(Vector({0.5, 0.5}), Vector({0, 0}), Vector({0, 0}));
  const SignedErrors now = SignedErrorsOf(Vector({1.5, 3.5}), Vector({1, 3}), Vector({1, 3}));
  const FlickerStats flicker = ComputeFlickers(before, now, all);
  EXPECT_DOUBLE_EQ(flicker.refined.rms, 0.0);
  EXPECT_DOUBLE_EQ(flicker.subdivided.rms, std::sqrt(5.0));
  EXPECT_DOUBLE_EQ(flicker.coarse.rms, std::sqrt(5.0));
  const FlickerStats none = ComputeFlickers(SignedErrors{}, now, all);
  EXPECT_TRUE(none.refined.empty() && none.subdivided.empty() && none.coarse.empty());
  EXPECT_TRUE(std::isnan(none.refined.rms));
}

}  // namespace
}  // namespace finecap
