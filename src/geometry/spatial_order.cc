#include "finecap/geometry/spatial_order.h"

#include <algorithm>
#include <cstdint>
#include <numeric>

namespace finecap {
namespace {

constexpr int kBitsPerAxis = 21;

// The 21 low bits of `value` spread to every third bit of the result.
uint64_t SpreadBits(uint64_t value) {
  value &= (uint64_t{1} << kBitsPerAxis) - 1;
  value = (value | value << 32) & 0x1f00000000ffffULL;
  value = (value | value << 16) & 0x1f0000ff0000ffULL;
  value = (value | value << 8) & 0x100f00f00f00f00fULL;
  value = (value | value << 4) & 0x10c30c30c30c30c3ULL;
  value = (value | value << 2) & 0x1249249249249249ULL;
  return value;
}

}  // namespace

std::vector<int> SpatialOrder(const Eigen::Matrix3Xd& points) {
  const int n = static_cast<int>(points.cols());
  Eigen::Vector3d lower = Eigen::Vector3d::Constant(0.0), upper = lower;
  bool any_finite = false;
  for (int i = 0; i < n; ++i) {
    if (!points.col(i).allFinite()) continue;
    lower = any_finite ? lower.cwiseMin(points.col(i)) : Eigen::Vector3d(points.col(i));
    upper = any_finite ? upper.cwiseMax(points.col(i)) : Eigen::Vector3d(points.col(i));
    any_finite = true;
  }
  const double extent = (upper - lower).maxCoeff();
  const double cells = static_cast<double>((uint64_t{1} << kBitsPerAxis) - 1);
  const double scale = extent > 0.0 ? cells / extent : 0.0;
  std::vector<uint64_t> codes(n, ~uint64_t{0});
  for (int i = 0; i < n; ++i) {
    if (!points.col(i).allFinite()) continue;
    const Eigen::Vector3d cell = ((points.col(i) - lower) * scale).cwiseMin(cells).cwiseMax(0.0);
    codes[i] = SpreadBits(static_cast<uint64_t>(cell.x())) |
               SpreadBits(static_cast<uint64_t>(cell.y())) << 1 |
               SpreadBits(static_cast<uint64_t>(cell.z())) << 2;
  }
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return codes[a] < codes[b]; });
  return order;
}

}  // namespace finecap
