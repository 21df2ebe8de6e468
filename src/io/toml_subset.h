// A strict reader of the part of TOML that calibration files use (not part of the public API).
//
// Debian 12 packages no maintained C++ TOML library (only the unmaintained cpptoml), and the
// Calib.toml files of Pose2Sim and anipose use a small part of the language: [table] headers
// with bare or quoted names, key = value lines, and values that are basic or literal strings,
// booleans, decimal integers and floats (inf and nan included), or arrays of these, nested and
// spread over several lines, with trailing commas and comments. That part is read exactly as the
// TOML 1.0 specification defines it. Everything else (dotted keys, inline tables, arrays of
// tables, multi-line strings, dates, hexadecimal, octal and binary integers) is refused with an
// Error that names the file, the line and what is not supported, as are duplicate keys and
// tables, which TOML forbids. Arrays nest at most kMaxTomlDepth deep, so that no input can
// exhaust the stack.
#ifndef FINECAP_SRC_TOML_SUBSET_H_
#define FINECAP_SRC_TOML_SUBSET_H_

#include <string>
#include <utility>
#include <vector>

namespace finecap {
namespace internal {

constexpr int kMaxTomlDepth = 8;

struct TomlValue {
  enum class Type { kString, kInteger, kFloat, kBool, kArray };
  Type type = Type::kString;
  std::string text;     // kString: the string, escapes resolved. Numbers: the token as written.
  double number = 0.0;  // kInteger, kFloat: the value (an integer as a double, exact to 2^53).
  bool boolean = false;
  std::vector<TomlValue> items;  // kArray.
  int line = 0;                  // Where the value starts, 1-based.

  bool IsNumber() const { return type == Type::kInteger || type == Type::kFloat; }
};

using TomlEntries = std::vector<std::pair<std::string, TomlValue>>;

struct TomlTable {
  std::string name;
  int line = 0;         // Of the [name] header.
  TomlEntries entries;  // In file order.
};

struct TomlDocument {
  TomlEntries root;               // Keys before the first table header.
  std::vector<TomlTable> tables;  // In file order.
};

// Parses `text`, the contents of `path` (named in errors).
TomlDocument ParseTomlSubset(const std::string& text, const std::string& path);

// "a string", "an integer", "a float", "a boolean", "an array": for error messages.
std::string TomlTypeName(const TomlValue& value);

}  // namespace internal
}  // namespace finecap

#endif  // FINECAP_SRC_TOML_SUBSET_H_
