// The names of the choices of options, as Ceres has StringToLinearSolverType and
// LinearSolverTypeToString: inside the library a choice is an enum; its names are spelled once,
// in one table of (value, name) pairs next to the enum, and used at the edges only: by the config
// schema (whose allowed values come from the table) and by the writers of stats and metrics.
//
// An enum `E` takes part by declaring, in its own namespace,
//
//   const std::vector<EnumName<E>>& EnumNames(E);
//
// which returns its table (the argument only selects the overload). EnumToString, StringToEnum and
// IsKnownEnum then work for it.
#ifndef FINECAP_UTIL_ENUM_NAMES_H_
#define FINECAP_UTIL_ENUM_NAMES_H_

#include <ostream>
#include <string>
#include <vector>

namespace finecap {

template <typename Enum>
struct EnumName {
  Enum value;
  const char* name;
};

// The name of `value`; "unknown" for a value outside the table (a cast from a wrong integer).
template <typename Enum>
std::string EnumToString(Enum value) {
  for (const EnumName<Enum>& entry : EnumNames(value)) {
    if (entry.value == value) return entry.name;
  }
  return "unknown";
}

// Sets `*value` to the choice named `name` (exact, lower case) and returns true; returns false,
// leaving `*value`, when no choice has that name.
template <typename Enum>
bool StringToEnum(const std::string& name, Enum* value) {
  for (const EnumName<Enum>& entry : EnumNames(*value)) {
    if (name == entry.name) {
      *value = entry.value;
      return true;
    }
  }
  return false;
}

// Whether `value` is one of the table's (Check()s use it against casts from wrong integers).
template <typename Enum>
bool IsKnownEnum(Enum value) {
  for (const EnumName<Enum>& entry : EnumNames(value)) {
    if (entry.value == value) return true;
  }
  return false;
}

// All names of the choices of `Enum`, in the table's order.
template <typename Enum>
std::vector<std::string> EnumNameList() {
  std::vector<std::string> names;
  for (const EnumName<Enum>& entry : EnumNames(Enum{})) names.push_back(entry.name);
  return names;
}

// Writes the name of `value`, so that a writer of stats or a cache key prints a choice as the
// config spells it.
template <typename Enum, typename = decltype(EnumNames(Enum{}))>
std::ostream& operator<<(std::ostream& out, Enum value) {
  return out << EnumToString(value);
}

// The names joined by ", ", for messages.
template <typename Enum>
std::string JoinedEnumNames() {
  std::string joined;
  for (const std::string& name : EnumNameList<Enum>())
    joined += (joined.empty() ? "" : ", ") + name;
  return joined;
}

}  // namespace finecap

#endif  // FINECAP_UTIL_ENUM_NAMES_H_
