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
#include "finecap/util/option_fields.h"

namespace finecap {
namespace internal {

inline std::string CheckNumberText(double value) {
  std::ostringstream text;
  text.precision(15);
  text << value;
  return text.str();
}

// Throws Error(field, ...) unless `value` is finite and in [min, max], in the words of a declared
// field's check (option_fields.h).
inline void RequireFieldRange(double value, double min, double max, const std::string& field) {
  OptionField range;
  range.min = min;
  range.max = max;
  CheckDeclaredNumber(value, range, field);
}

// Throws Error(field, ...) unless `value` is one of its enum's choices (not a cast from a wrong
// integer).
template <typename Enum>
void RequireKnownChoice(Enum value, const std::string& field) {
  CheckDeclaredChoice(IsKnownEnum(value), static_cast<int>(value), field);
}

}  // namespace internal
}  // namespace finecap

#endif  // FINECAP_SRC_OPTION_CHECKS_H_
