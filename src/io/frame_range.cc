#include "finecap/io/frame_range.h"

#include <algorithm>
#include <cctype>

#include "finecap/util/error.h"

namespace finecap {
namespace {

int ParseIndex(const std::string& text, const std::string& where, int if_empty) {
  if (text.empty()) return if_empty;
  const bool digits =
      std::all_of(text.begin(), text.end(), [](unsigned char c) { return std::isdigit(c); });
  Require(digits && text.size() < 10, where, "'" + text + "' is not a frame index");
  return std::stoi(text);
}

}  // namespace

FrameRange FrameRange::ClippedTo(int num_frames) const {
  return {std::min(begin, num_frames), std::min(end, num_frames)};
}

FrameRange ParseFrameRange(const std::string& text, const std::string& where) {
  const std::string message = "expected A:B, A:, :B or A (frame indices), got '" + text + "'";
  const size_t colon = text.find(':');
  FrameRange range;
  if (colon == std::string::npos) {
    if (text.empty()) return range;
    range.begin = ParseIndex(text, where, 0);
    range.end = range.begin + 1;
    return range;
  }
  Require(text.find(':', colon + 1) == std::string::npos, where, message);
  range.begin = ParseIndex(text.substr(0, colon), where, 0);
  range.end = ParseIndex(text.substr(colon + 1), where, range.end);
  Require(range.end > range.begin, where, "the range '" + text + "' holds no frame");
  return range;
}

}  // namespace finecap
