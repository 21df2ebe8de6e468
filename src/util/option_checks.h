// Helpers of the options structs' Check()s for what their declared fields (option_fields.h) do not
// say, such as a bound that is another field: each names the C++ field it checks
// ("VisibilityOptions::fallback_view_angle_deg"), never a config key (the config layer maps one to
// the other), and states the allowed values in the problem.
#ifndef FINECAP_SRC_OPTION_CHECKS_H_
#define FINECAP_SRC_OPTION_CHECKS_H_

#include <cmath>
#include <sstream>
#include <string>

#include "finecap/util/enum_names.h"
#include "finecap/util/error.h"

namespace finecap {
namespace internal {

inline std::string CheckNumberText(double value) {
  std::ostringstream text;
  text.precision(15);
  text << value;
  return text.str();
}

// Throws Error(field, ...) unless `value` is finite and in [min, max].
inline void RequireFieldRange(double value, double min, double max, const std::string& field) {
  Require(std::isfinite(value), field, "must be a finite number");
  Require(value >= min && value <= max, field,
          "is " + CheckNumberText(value) + " but must lie in [" + CheckNumberText(min) + ", " +
              CheckNumberText(max) + "]");
}

// Throws Error(field, ...) unless min <= value <= max.
inline void RequireFieldRange(int value, int min, int max, const std::string& field) {
  Require(value >= min && value <= max, field,
          "is " + std::to_string(value) + " but must lie in [" + std::to_string(min) + ", " +
              std::to_string(max) + "]");
}

// Throws Error(field, ...) unless `value` is one of its enum's choices (not a cast from a wrong
// integer).
template <typename Enum>
void RequireKnownChoice(Enum value, const std::string& field) {
  Require(IsKnownEnum(value), field,
          "is not a valid choice (value " + std::to_string(static_cast<int>(value)) + ")");
}

}  // namespace internal
}  // namespace finecap

#endif  // FINECAP_SRC_OPTION_CHECKS_H_
