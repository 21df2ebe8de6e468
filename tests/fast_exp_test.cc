#include "util/fast_exp.h"

#include <cmath>

#include <gtest/gtest.h>

namespace finecap {
namespace {

// Within its stated relative error of the library's exp over the whole range it takes, on a grid
// fine enough to land between every pair of its range reductions' integers many times.
TEST(FastExpTest, AgreesWithTheLibraryOverItsRange) {
  double worst = 0.0;
  for (int i = 0; i <= 1000000; ++i) {
    const float x = -87.0f * static_cast<float>(i) / 1000000.0f;
    const double exact = std::exp(static_cast<double>(x));
    const double fast = internal::FastExpNonPositive(x);
    worst = std::max(worst, std::abs(fast - exact) / exact);
  }
  EXPECT_LT(worst, 3e-7);
}

TEST(FastExpTest, ExactAtZeroAndZeroFarBelowTheRange) {
  EXPECT_EQ(internal::FastExpNonPositive(0.0f), 1.0f);
  EXPECT_EQ(internal::FastExpNonPositive(-200.0f), 0.0f);
  EXPECT_EQ(internal::FastExpNonPositive(-1e30f), 0.0f);
}

}  // namespace
}  // namespace finecap
