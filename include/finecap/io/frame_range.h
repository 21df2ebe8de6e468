// A half-open range of frame indices [begin, end) into a capture's sorted frame list.
#ifndef FINECAP_FRAME_RANGE_H_
#define FINECAP_FRAME_RANGE_H_

#include <limits>
#include <string>

namespace finecap {

struct FrameRange {
  int begin = 0;
  int end = std::numeric_limits<int>::max();  // Exclusive; max() = up to the last frame.

  // The range clipped to a sequence of `num_frames` frames.
  FrameRange ClippedTo(int num_frames) const;
  int size() const { return end > begin ? end - begin : 0; }
};

// Parses "A:B" (frames A to B-1), "A:" (A to the last), ":B", "A" (just A) or "" (all).
// Throws Error(where, ...) on anything else or on B <= A.
FrameRange ParseFrameRange(const std::string& text, const std::string& where);

}  // namespace finecap

#endif  // FINECAP_FRAME_RANGE_H_
