#include "finecap/geometry/spatial_order.h"

#include <algorithm>
#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace finecap {
namespace {

TEST(SpatialOrderTest, IsAPermutationWithNonFinitePointsLast) {
  Eigen::Matrix3Xd points(3, 5);
  points << 1, std::nan(""), 0, 2, 0,  //
      0, 0, 0, 2, 1,                   //
      0, 0, 0, 2, 0;
  const std::vector<int> order = SpatialOrder(points);
  ASSERT_EQ(order.size(), 5u);
  EXPECT_TRUE(
      std::is_permutation(order.begin(), order.end(), std::vector<int>{0, 1, 2, 3, 4}.begin()));
  EXPECT_EQ(order.back(), 1);
  EXPECT_EQ(order.front(), 2);  // The box's lowest corner comes first.
  EXPECT_EQ(order[3], 3);       // Its highest last among the finite ones.
}

TEST(SpatialOrderTest, KeepsNeighboursCloseInTheOrder) {
  // A grid of points shuffled: along the order, consecutive points must be far closer on
  // average than consecutive points of the shuffle.
  std::vector<Eigen::Vector3d> grid;
  for (int x = 0; x < 32; ++x)
    for (int y = 0; y < 32; ++y) grid.emplace_back(x, y, 0.5 * x);
  std::shuffle(grid.begin(), grid.end(), std::mt19937(7));
  Eigen::Matrix3Xd points(3, grid.size());
  for (size_t i = 0; i < grid.size(); ++i) points.col(i) = grid[i];
  const auto mean_step = [&](const std::vector<int>& order) {
    double sum = 0.0;
    for (size_t i = 1; i < order.size(); ++i)
      sum += (points.col(order[i]) - points.col(order[i - 1])).norm();
    return sum / (order.size() - 1);
  };
  std::vector<int> identity(grid.size());
  for (size_t i = 0; i < identity.size(); ++i) identity[i] = static_cast<int>(i);
  const double spatial = mean_step(SpatialOrder(points));
  EXPECT_LT(spatial, 2.0);
  EXPECT_GT(mean_step(identity), 5.0 * spatial);
}

TEST(SpatialOrderTest, CoincidentPointsKeepTheirIndexOrder) {
  const Eigen::Matrix3Xd points = Eigen::Matrix3Xd::Ones(3, 4);
  EXPECT_EQ(SpatialOrder(points), (std::vector<int>{0, 1, 2, 3}));
}

}  // namespace
}  // namespace finecap
