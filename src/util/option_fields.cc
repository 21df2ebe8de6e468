#include "finecap/util/option_fields.h"

#include <cmath>

#include "finecap/util/error.h"
#include "util/option_checks.h"

namespace finecap {

bool OptionField::HasMin() const { return min != std::numeric_limits<double>::lowest(); }

bool OptionField::HasMax() const { return max != std::numeric_limits<double>::max(); }

namespace internal {
namespace {

// "lie in [1, 10]", "be >= 0", "be 0 (off) or lie in [3, 1000]".
std::string AllowedText(const OptionField& field) {
  std::string range;
  if (field.HasMin() && field.HasMax()) {
    range = "lie in [" + CheckNumberText(field.min) + ", " + CheckNumberText(field.max) + "]";
  } else if (field.HasMin()) {
    range = "be >= " + CheckNumberText(field.min);
  } else {
    range = "be <= " + CheckNumberText(field.max);
  }
  return field.zero_also ? "be 0 (off) or " + range : range;
}

bool IsAllowed(double value, const OptionField& field) {
  return (field.zero_also && value == 0.0) || (value >= field.min && value <= field.max);
}

}  // namespace

void CheckDeclaredNumber(double value, const OptionField& field, const std::string& field_name) {
  Require(std::isfinite(value), field_name, "must be a finite number");
  Require(IsAllowed(value, field), field_name,
          "is " + CheckNumberText(value) + " but must " + AllowedText(field));
}

void CheckDeclaredNumbers(const double* values, int count, const OptionField& field,
                          const std::string& field_name) {
  for (int i = 0; i < count; ++i) CheckDeclaredNumber(values[i], field, field_name);
}

void CheckDeclaredChoice(bool known, int value, const std::string& field_name) {
  Require(known, field_name, "is not a valid choice (value " + std::to_string(value) + ")");
}

}  // namespace internal
}  // namespace finecap
