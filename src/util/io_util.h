// Small helpers shared by the file readers and writers: files, numbers, JSON text, PNG (not part
// of the public API).
#ifndef FINECAP_SRC_UTIL_IO_UTIL_H_
#define FINECAP_SRC_UTIL_IO_UTIL_H_

#include <array>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace finecap {
namespace internal {

// Throws Error(path, ...) unless `path` is an existing regular file.
void RequireFile(const std::string& path);

// The whole file as bytes. Throws Error naming the file when it is missing or unreadable.
std::string ReadWholeFile(const std::string& path);

// Parses the whole of `token` as a number; false when it is not one (or has trailing characters).
bool ParseDouble(const std::string& token, double* value);
bool ParseInt(const std::string& token, int* value);

// "a, b, c": names listed in an error message.
std::string JoinWithCommas(const std::vector<std::string>& names);

// Whitespace-separated tokens of `line`.
std::vector<std::string> SplitWhitespace(const std::string& line);

// `text` as a JSON string literal: quoted, with quotes, backslashes and control characters
// escaped.
std::string JsonString(const std::string& text);

// `value` as a JSON number with 10 significant digits; "null" when it is not finite (JSON has no
// NaN or infinity).
std::string JsonNumber(double value);

// Encodes `image` (8- or 16-bit, 1, 3 or 4 channels) as PNG and writes it to `path` atomically.
// Throws Error naming the file when it cannot be encoded or written.
void WritePng(const std::string& path, const cv::Mat& image);

}  // namespace internal
}  // namespace finecap

#endif  // FINECAP_SRC_UTIL_IO_UTIL_H_
