#include "util/io_util.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
#include <sstream>

#include "finecap/util/atomic_file.h"
#include "finecap/util/error.h"
#include "util/image_codec.h"

namespace finecap {
namespace internal {

void RequireFile(const std::string& path) {
  std::error_code error;
  Require(std::filesystem::exists(path, error), path, "file not found");
  Require(std::filesystem::is_regular_file(path, error), path, "is not a regular file");
}

std::string ReadWholeFile(const std::string& path) {
  RequireFile(path);
  std::ifstream stream(path, std::ios::binary);
  Require(static_cast<bool>(stream), path, "cannot open the file for reading");
  std::ostringstream contents;
  contents << stream.rdbuf();
  Require(!stream.bad(), path, "read error");
  return contents.str();
}

bool ParseDouble(const std::string& token, double* value) {
  if (token.empty()) return false;
  char* end = nullptr;
  errno = 0;
  *value = std::strtod(token.c_str(), &end);
  return end == token.c_str() + token.size() && errno != ERANGE;
}

bool ParseInt(const std::string& token, int* value) {
  if (token.empty()) return false;
  char* end = nullptr;
  errno = 0;
  const long parsed = std::strtol(token.c_str(), &end, 10);
  if (end != token.c_str() + token.size() || errno == ERANGE) return false;
  if (parsed < std::numeric_limits<int>::min() || parsed > std::numeric_limits<int>::max()) {
    return false;
  }
  *value = static_cast<int>(parsed);
  return true;
}

std::string JoinWithCommas(const std::vector<std::string>& names) {
  std::string list;
  for (const std::string& name : names) list += (list.empty() ? "" : ", ") + name;
  return list;
}

std::vector<std::string> SplitWhitespace(const std::string& line) {
  std::istringstream stream(line);
  std::vector<std::string> tokens;
  for (std::string token; stream >> token;) tokens.push_back(token);
  return tokens;
}

std::string JsonString(const std::string& text) {
  std::string quoted = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\') {
      quoted += '\\';
      quoted += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char escaped[8];
      std::snprintf(escaped, sizeof(escaped), "\\u%04x", c);
      quoted += escaped;
    } else {
      quoted += c;
    }
  }
  return quoted + "\"";
}

std::string JsonNumber(double value) {
  if (!std::isfinite(value)) return "null";
  std::ostringstream text;
  text << std::setprecision(10) << value;
  return text.str();
}

void WritePng(const std::string& path, const cv::Mat& image) {
  WriteTextFileAtomically(path, EncodePng(image, path));
}

}  // namespace internal
}  // namespace finecap
