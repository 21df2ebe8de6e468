// One part of a frame range split for independent processes (cluster array tasks): the range is
// cut into `count` contiguous parts whose sizes differ by at most one frame, the first parts
// taking the extra frames. Shards are numbered from 0, as Slurm's SLURM_ARRAY_TASK_ID is with
// `--array=0-(N-1)`.
#ifndef FINECAP_REFINE_SHARD_H_
#define FINECAP_REFINE_SHARD_H_

#include <string>

#include "finecap/io/frame_range.h"

namespace finecap {

struct Shard {
  // Which part, 0-based: 0 <= index < count. Default 0.
  int index = 0;
  // Into how many parts the range is cut, >= 1. Default 1 (the whole range).
  int count = 1;

  // Throws Error("shard", ...) unless 0 <= index < count.
  void Check() const;
  // "I/N", as ParseShard reads it.
  std::string ToString() const;
};

// Parses "I/N" (0 <= I < N, both decimal integers) or "" (the whole range, 0/1). Throws
// Error(where, problem) on anything else, e.g. "4/4" or "1/0".
Shard ParseShard(const std::string& text, const std::string& where);

// Part `shard.index` of `range` (which must be finite: clip it to the capture first). With more
// parts than frames, some parts are empty.
FrameRange ShardOf(const FrameRange& range, const Shard& shard);

}  // namespace finecap

#endif  // FINECAP_REFINE_SHARD_H_
