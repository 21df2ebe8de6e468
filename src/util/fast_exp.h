// exp(x) in single precision for x <= 0, written so that a compiler vectorises a loop that calls it
// (std::exp is a library call per element, which no loop around it can vectorise without
// -ffast-math).
//
// exp(x) = 2^n exp(r) with n = round(x / ln 2) and |r| <= ln(2) / 2; exp(r) by its Taylor series to
// r^6, whose remainder is below 2e-8 of the result there, and 2^n built in the float's exponent
// bits. Relative error within 3e-7 (a few units in the last place) for x in [-87, 0]; below -87 the
// result is 0 (exp(-87) is 1.6e-38, near the smallest normal float).
#ifndef FINECAP_SRC_UTIL_FAST_EXP_H_
#define FINECAP_SRC_UTIL_FAST_EXP_H_

#include <cstdint>
#include <cstring>

namespace finecap {
namespace internal {

inline float FastExpNonPositive(float x) {
  constexpr float kLowest = -87.0f;
  constexpr float kLog2E = 1.44269504f;
  // ln 2 in two parts: n * kLn2High is exact for the n that occur, so r keeps its digits.
  constexpr float kLn2High = 0.693359375f;
  constexpr float kLn2Low = -2.12194440e-4f;
  // Adding and subtracting 1.5 * 2^23 rounds to the nearest integer without a library call.
  constexpr float kRound = 12582912.0f;
  const bool underflow = x < kLowest;
  x = underflow ? kLowest : x;
  const float n = (x * kLog2E + kRound) - kRound;
  const float r = (x - n * kLn2High) - n * kLn2Low;
  float p = 1.0f / 720.0f;
  p = p * r + 1.0f / 120.0f;
  p = p * r + 1.0f / 24.0f;
  p = p * r + 1.0f / 6.0f;
  p = p * r + 0.5f;
  p = p * r + 1.0f;
  p = p * r + 1.0f;
  const int32_t exponent_bits = (static_cast<int32_t>(n) + 127) << 23;
  float scale;
  std::memcpy(&scale, &exponent_bits, sizeof(scale));
  return underflow ? 0.0f : p * scale;
}

}  // namespace internal
}  // namespace finecap

#endif  // FINECAP_SRC_UTIL_FAST_EXP_H_
