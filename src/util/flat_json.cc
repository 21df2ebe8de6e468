#include "util/flat_json.h"

#include <cctype>
#include <cstring>
#include <set>

#include "finecap/util/error.h"
#include "util/io_util.h"

namespace finecap {
namespace internal {
namespace {

using Members = std::vector<std::pair<std::string, FlatJsonValue>>;

// A cursor over the text; every failure names the character offset, since a record is one line.
class Reader {
 public:
  Reader(const std::string& text, const std::string& where) : text_(text), where_(where) {}

  Members Object() {
    Expect('{');
    Members members;
    std::set<std::string> keys;
    if (!Consume('}')) {
      do {
        std::string key = String();
        Require(keys.insert(key).second, where_, "key \"" + key + "\" appears twice");
        Expect(':');
        members.emplace_back(std::move(key), Value());
      } while (Consume(','));
      Expect('}');
    }
    SkipSpace();
    Require(position_ == text_.size(), where_, Problem("unexpected text after the object"));
    return members;
  }

 private:
  FlatJsonValue Value() {
    SkipSpace();
    FlatJsonValue value;
    const char next = Peek();
    if (next == '"') {
      value.kind = FlatJsonValue::Kind::kString;
      value.text = String();
    } else if (next == '[') {
      value.kind = FlatJsonValue::Kind::kStringList;
      value.texts = StringList();
    } else if (Word("true") || Word("false")) {
      value.kind = FlatJsonValue::Kind::kBool;
      value.boolean = text_.compare(position_ - 4, 4, "true") == 0;
    } else if (Word("null")) {
      value.kind = FlatJsonValue::Kind::kNull;
    } else {
      value.kind = FlatJsonValue::Kind::kNumber;
      value.number = Number();
    }
    return value;
  }

  std::vector<std::string> StringList() {
    Expect('[');
    std::vector<std::string> texts;
    if (Consume(']')) return texts;
    do {
      texts.push_back(String());
    } while (Consume(','));
    Expect(']');
    return texts;
  }

  double Number() {
    const size_t start = position_;
    while (position_ < text_.size() && std::strchr("+-0123456789.eE", text_[position_]) &&
           text_[position_] != '\0') {
      ++position_;
    }
    double number = 0.0;
    Require(position_ > start && ParseDouble(text_.substr(start, position_ - start), &number),
            where_, Problem("expected a value (string, number, true, false, null or list)", start));
    return number;
  }

  std::string String() {
    Expect('"');
    std::string result;
    while (true) {
      Require(position_ < text_.size(), where_, Problem("unterminated string"));
      const char c = text_[position_++];
      if (c == '"') return result;
      Require(static_cast<unsigned char>(c) >= 0x20, where_,
              Problem("control character inside a string", position_ - 1));
      if (c != '\\') {
        result += c;
        continue;
      }
      Escape(&result);
    }
  }

  void Escape(std::string* result) {
    Require(position_ < text_.size(), where_, Problem("unterminated string"));
    const char c = text_[position_++];
    static const std::string kSimple = "\"\\/bfnrt";
    static const std::string kMeaning = "\"\\/\b\f\n\r\t";
    const size_t simple = kSimple.find(c);
    if (simple != std::string::npos) {
      *result += kMeaning[simple];
      return;
    }
    Require(c == 'u', where_, Problem("unknown escape in a string", position_ - 1));
    AppendUtf8(HexCodePoint(), result);
  }

  unsigned HexCodePoint() {
    Require(position_ + 4 <= text_.size(), where_, Problem("\\u needs four hex digits"));
    unsigned code = 0;
    for (int i = 0; i < 4; ++i) {
      const char c = text_[position_++];
      Require(std::isxdigit(static_cast<unsigned char>(c)) != 0, where_,
              Problem("\\u needs four hex digits", position_ - 1));
      code = code * 16 + static_cast<unsigned>(std::isdigit(static_cast<unsigned char>(c))
                                                   ? c - '0'
                                                   : std::tolower(c) - 'a' + 10);
    }
    // finecap escapes control characters only; a lone UTF-16 surrogate has no UTF-8 form.
    Require(code < 0xD800 || code > 0xDFFF, where_, Problem("\\u escape of a UTF-16 surrogate"));
    return code;
  }

  static void AppendUtf8(unsigned code, std::string* result) {
    if (code < 0x80) {
      *result += static_cast<char>(code);
    } else if (code < 0x800) {
      *result += static_cast<char>(0xC0 | (code >> 6));
      *result += static_cast<char>(0x80 | (code & 0x3F));
    } else {
      *result += static_cast<char>(0xE0 | (code >> 12));
      *result += static_cast<char>(0x80 | ((code >> 6) & 0x3F));
      *result += static_cast<char>(0x80 | (code & 0x3F));
    }
  }

  bool Word(const char* word) {
    const std::string expected(word);
    if (text_.compare(position_, expected.size(), expected) != 0) return false;
    position_ += expected.size();
    return true;
  }

  void SkipSpace() {
    while (position_ < text_.size() && std::strchr(" \t\r\n", text_[position_]) &&
           text_[position_] != '\0') {
      ++position_;
    }
  }

  char Peek() const { return position_ < text_.size() ? text_[position_] : '\0'; }

  bool Consume(char c) {
    SkipSpace();
    if (Peek() != c) return false;
    ++position_;
    return true;
  }

  void Expect(char c) { Require(Consume(c), where_, Problem(std::string("expected '") + c + "'")); }

  std::string Problem(const std::string& what) const { return Problem(what, position_); }
  std::string Problem(const std::string& what, size_t at) const {
    return what + " at character " + std::to_string(at + 1);
  }

  const std::string& text_;
  const std::string& where_;
  size_t position_ = 0;
};

}  // namespace

Members ParseFlatJsonObject(const std::string& text, const std::string& where) {
  return Reader(text, where).Object();
}

}  // namespace internal
}  // namespace finecap
