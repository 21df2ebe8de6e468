#include "io/toml_subset.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <set>

#include "finecap/util/error.h"

namespace finecap {
namespace internal {
namespace {

bool IsDigit(char c) { return c >= '0' && c <= '9'; }

bool IsBareKeyChar(char c) {
  return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || IsDigit(c) || c == '_' || c == '-';
}

// Characters that can make up a number, a boolean or one of the refused forms (dates, hex).
bool IsTokenChar(char c) { return IsBareKeyChar(c) || c == '+' || c == '.' || c == ':'; }

// Digits with single underscores between them, as TOML writes long numbers ("1_000").
bool IsDigitRun(const std::string& s, size_t begin, size_t end) {
  if (begin >= end || !IsDigit(s[begin]) || !IsDigit(s[end - 1])) return false;
  for (size_t i = begin; i < end; ++i) {
    if (s[i] == '_' && (!IsDigit(s[i - 1]) || !IsDigit(s[i + 1]))) return false;
    if (s[i] != '_' && !IsDigit(s[i])) return false;
  }
  return true;
}

// TOML's decimal integer or float: [+-] (inf | nan | int [. digits] [e [+-] digits]), where int
// has no leading zero. `is_integer` tells which of the two it is.
bool IsTomlDecimal(const std::string& token, bool* is_integer) {
  size_t i = (!token.empty() && (token[0] == '+' || token[0] == '-')) ? 1 : 0;
  const std::string body = token.substr(i);
  *is_integer = false;
  if (body == "inf" || body == "nan") return true;
  const size_t dot = token.find('.', i);
  const size_t exponent = token.find_first_of("eE", i);
  const size_t int_end = std::min({dot, exponent, token.size()});
  if (!IsDigitRun(token, i, int_end)) return false;
  if (token[i] == '0' && int_end > i + 1) return false;  // Leading zero.
  size_t next = int_end;
  if (dot != std::string::npos) {
    if (dot != int_end) return false;
    const size_t fraction_end = std::min(exponent, token.size());
    if (!IsDigitRun(token, dot + 1, fraction_end)) return false;
    next = fraction_end;
  }
  if (exponent != std::string::npos) {
    if (exponent != next) return false;
    size_t digits = exponent + 1;
    if (digits < token.size() && (token[digits] == '+' || token[digits] == '-')) ++digits;
    if (!IsDigitRun(token, digits, token.size())) return false;
    next = token.size();
  }
  *is_integer = dot == std::string::npos && exponent == std::string::npos;
  return next == token.size();
}

void AppendUtf8(unsigned long code_point, std::string* out) {
  if (code_point < 0x80) {
    *out += static_cast<char>(code_point);
  } else if (code_point < 0x800) {
    *out += static_cast<char>(0xc0 | (code_point >> 6));
    *out += static_cast<char>(0x80 | (code_point & 0x3f));
  } else if (code_point < 0x10000) {
    *out += static_cast<char>(0xe0 | (code_point >> 12));
    *out += static_cast<char>(0x80 | ((code_point >> 6) & 0x3f));
    *out += static_cast<char>(0x80 | (code_point & 0x3f));
  } else {
    *out += static_cast<char>(0xf0 | (code_point >> 18));
    *out += static_cast<char>(0x80 | ((code_point >> 12) & 0x3f));
    *out += static_cast<char>(0x80 | ((code_point >> 6) & 0x3f));
    *out += static_cast<char>(0x80 | (code_point & 0x3f));
  }
}

class Parser {
 public:
  Parser(const std::string& text, const std::string& path) : text_(text), path_(path) {}

  TomlDocument Parse() {
    TomlDocument document;
    TomlEntries* entries = &document.root;
    std::set<std::string> table_names;
    while (SkipBlankLinesAndComments()) {
      if (Peek() == '[') {
        TomlTable table = ParseTableHeader();
        Require(table_names.insert(table.name).second, Here(),
                "table [" + table.name + "] appears twice");
        document.tables.push_back(std::move(table));
        entries = &document.tables.back().entries;
      } else {
        ParseKeyValue(entries);
      }
      ExpectEndOfLine();
    }
    return document;
  }

 private:
  std::string Here() const { return path_ + " line " + std::to_string(line_); }
  bool AtEnd() const { return position_ >= text_.size(); }
  char Peek(size_t ahead = 0) const {
    return position_ + ahead < text_.size() ? text_[position_ + ahead] : '\0';
  }
  [[noreturn]] void Fail(const std::string& problem) const { throw Error(Here(), problem); }

  // What the character at the current position is, for "unexpected ..." messages.
  std::string Describe() const {
    if (AtEnd()) return "the end of the file";
    const unsigned char c = static_cast<unsigned char>(Peek());
    if (c == '\n') return "the end of the line";
    if (c < 0x20 || c == 0x7f) return "control character " + std::to_string(c);
    return std::string("'") + Peek() + "'";
  }

  void SkipSpaces() {
    while (Peek() == ' ' || Peek() == '\t') ++position_;
  }

  void SkipComment() {
    if (Peek() != '#') return;
    while (!AtEnd() && Peek() != '\n') {
      const unsigned char c = static_cast<unsigned char>(Peek());
      if ((c < 0x20 && c != '\t' && !(c == '\r' && Peek(1) == '\n')) || c == 0x7f) {
        Fail("control character " + std::to_string(c) + " in a comment");
      }
      ++position_;
    }
  }

  // Consumes one line break ("\n" or "\r\n"); false when there is none here.
  bool SkipNewline() {
    if (Peek() == '\r' && Peek(1) == '\n') ++position_;
    if (Peek() != '\n') return false;
    ++position_;
    ++line_;
    return true;
  }

  // Skips empty lines, spaces and comments; false at the end of the file.
  bool SkipBlankLinesAndComments() {
    for (;;) {
      SkipSpaces();
      SkipComment();
      if (AtEnd()) return false;
      if (!SkipNewline()) return true;
    }
  }

  void ExpectEndOfLine() {
    SkipSpaces();
    SkipComment();
    if (AtEnd() || SkipNewline()) return;
    Fail("expected the end of the line, found " + Describe());
  }

  std::string ParseKey() {
    if (Peek() == '"' || Peek() == '\'') return ParseString();
    const size_t start = position_;
    while (IsBareKeyChar(Peek())) ++position_;
    if (position_ == start) Fail("expected a key, found " + Describe());
    return text_.substr(start, position_ - start);
  }

  void RefuseDottedKey(const std::string& key) {
    SkipSpaces();
    if (Peek() == '.') {
      Fail("dotted keys ('" + key +
           ".name') are not supported: write each table as a [name] header");
    }
  }

  TomlTable ParseTableHeader() {
    ++position_;  // '['
    if (Peek() == '[') Fail("arrays of tables ([[name]]) are not supported");
    SkipSpaces();
    TomlTable table;
    table.line = line_;
    table.name = ParseKey();
    RefuseDottedKey(table.name);
    if (Peek() != ']') Fail("expected ']' after the table name, found " + Describe());
    ++position_;
    return table;
  }

  void ParseKeyValue(TomlEntries* entries) {
    const std::string key = ParseKey();
    RefuseDottedKey(key);
    if (Peek() != '=') Fail("expected '=' after key '" + key + "', found " + Describe());
    ++position_;
    SkipSpaces();
    for (const auto& entry : *entries) {
      if (entry.first == key) Fail("key '" + key + "' appears twice in the same table");
    }
    TomlValue value = ParseValue(0);
    entries->emplace_back(key, std::move(value));
  }

  TomlValue ParseValue(int depth) {
    TomlValue value;
    value.line = line_;
    const char c = Peek();
    if (c == '"' || c == '\'') {
      value.type = TomlValue::Type::kString;
      value.text = ParseString();
    } else if (c == '[') {
      value.type = TomlValue::Type::kArray;
      value.items = ParseArray(depth);
    } else if (c == '{') {
      Fail("inline tables ({...}) are not supported");
    } else if (IsTokenChar(c)) {
      ParseScalarToken(&value);
    } else {
      Fail("expected a value, found " + Describe());
    }
    return value;
  }

  std::vector<TomlValue> ParseArray(int depth) {
    if (depth + 1 > kMaxTomlDepth) {
      Fail("arrays nested more than " + std::to_string(kMaxTomlDepth) + " deep");
    }
    ++position_;  // '['
    std::vector<TomlValue> items;
    for (;;) {
      SkipArraySpace();
      if (Peek() == ']') break;
      items.push_back(ParseValue(depth + 1));
      SkipArraySpace();
      if (Peek() == ',') {
        ++position_;
        continue;
      }
      if (Peek() != ']') Fail("expected ',' or ']' in an array, found " + Describe());
    }
    ++position_;  // ']'
    return items;
  }

  // Inside an array, line breaks and comments are white space.
  void SkipArraySpace() {
    for (;;) {
      SkipSpaces();
      SkipComment();
      if (AtEnd()) Fail("unterminated array (no closing ']')");
      if (!SkipNewline()) return;
    }
  }

  void ParseScalarToken(TomlValue* value) {
    const size_t start = position_;
    while (IsTokenChar(Peek())) ++position_;
    const std::string token = text_.substr(start, position_ - start);
    value->text = token;
    if (token == "true" || token == "false") {
      value->type = TomlValue::Type::kBool;
      value->boolean = token == "true";
      return;
    }
    bool is_integer = false;
    if (!IsTomlDecimal(token, &is_integer)) {
      Fail("'" + token +
           "' is not a value this reader understands (a decimal number, true, false, a quoted "
           "string or an array; dates and hexadecimal, octal or binary numbers are not "
           "supported)");
    }
    std::string digits;
    for (char c : token) {
      if (c != '_') digits += c;
    }
    errno = 0;
    value->number = std::strtod(digits.c_str(), nullptr);
    if (errno == ERANGE && std::isinf(value->number)) Fail("'" + token + "' is out of range");
    value->type = is_integer ? TomlValue::Type::kInteger : TomlValue::Type::kFloat;
  }

  std::string ParseString() {
    const char quote = Peek();
    if (Peek(1) == quote && Peek(2) == quote) Fail("multi-line strings are not supported");
    ++position_;
    std::string result;
    for (;;) {
      if (AtEnd() || Peek() == '\n') Fail("unterminated string");
      const char c = Peek();
      const unsigned char u = static_cast<unsigned char>(c);
      ++position_;
      if (c == quote) return result;
      if ((u < 0x20 && c != '\t') || u == 0x7f) {
        Fail("control character " + std::to_string(u) + " in a string (write it as an escape)");
      }
      if (c == '\\' && quote == '"') {
        ParseEscape(&result);
      } else {
        result += c;
      }
    }
  }

  void ParseEscape(std::string* out) {
    const char c = Peek();
    ++position_;
    switch (c) {
      case 'b':
        *out += '\b';
        return;
      case 't':
        *out += '\t';
        return;
      case 'n':
        *out += '\n';
        return;
      case 'f':
        *out += '\f';
        return;
      case 'r':
        *out += '\r';
        return;
      case '"':
        *out += '"';
        return;
      case '\\':
        *out += '\\';
        return;
      case 'u':
        AppendUtf8(ParseHex(4), out);
        return;
      case 'U':
        AppendUtf8(ParseHex(8), out);
        return;
      default:
        break;
    }
    --position_;
    Fail("unknown escape '\\" + std::string(AtEnd() ? "" : std::string(1, c)) + "' in a string");
  }

  unsigned long ParseHex(int digits) {
    unsigned long code_point = 0;
    for (int i = 0; i < digits; ++i) {
      const char c = Peek();
      int digit = -1;
      if (IsDigit(c)) digit = c - '0';
      if (c >= 'a' && c <= 'f') digit = c - 'a' + 10;
      if (c >= 'A' && c <= 'F') digit = c - 'A' + 10;
      if (digit < 0) Fail("a \\u or \\U escape needs " + std::to_string(digits) + " hex digits");
      code_point = code_point * 16 + static_cast<unsigned long>(digit);
      ++position_;
    }
    if (code_point > 0x10ffff || (code_point >= 0xd800 && code_point <= 0xdfff)) {
      Fail("escape names no Unicode scalar value");
    }
    return code_point;
  }

  const std::string& text_;
  const std::string& path_;
  size_t position_ = 0;
  int line_ = 1;
};

}  // namespace

TomlDocument ParseTomlSubset(const std::string& text, const std::string& path) {
  return Parser(text, path).Parse();
}

std::string TomlTypeName(const TomlValue& value) {
  switch (value.type) {
    case TomlValue::Type::kString:
      return "a string";
    case TomlValue::Type::kInteger:
      return "an integer";
    case TomlValue::Type::kFloat:
      return "a float";
    case TomlValue::Type::kBool:
      return "a boolean";
    case TomlValue::Type::kArray:
      return "an array";
  }
  return "a value";
}

}  // namespace internal
}  // namespace finecap
