// A reader for the flat JSON objects finecap writes, one per line (stats.jsonl): string, number,
// true/false, null and list-of-string values, no nesting (not part of the public API).
#ifndef FINECAP_SRC_UTIL_FLAT_JSON_H_
#define FINECAP_SRC_UTIL_FLAT_JSON_H_

#include <string>
#include <utility>
#include <vector>

namespace finecap {
namespace internal {

// One value of a flat JSON object.
struct FlatJsonValue {
  enum class Kind { kString, kNumber, kBool, kNull, kStringList };
  Kind kind = Kind::kNull;
  std::string text;                // kString.
  double number = 0.0;             // kNumber.
  bool boolean = false;            // kBool.
  std::vector<std::string> texts;  // kStringList.
};

// The members of the JSON object `text` in file order. Whitespace around tokens is allowed;
// anything after the closing brace but whitespace is refused. Strings take JSON's escapes
// (\uXXXX outside the surrogate range). Throws Error(where, ...) saying what is wrong and at which
// character; a key given twice is refused too.
std::vector<std::pair<std::string, FlatJsonValue>> ParseFlatJsonObject(const std::string& text,
                                                                       const std::string& where);

}  // namespace internal
}  // namespace finecap

#endif  // FINECAP_SRC_UTIL_FLAT_JSON_H_
