#include "finecap/refine/shard.h"

#include <algorithm>

#include "finecap/util/error.h"
#include "util/io_util.h"

namespace finecap {

void Shard::Check() const {
  Require(count >= 1 && index >= 0 && index < count, "shard",
          "expected 0 <= I < N in I/N (shards are numbered from 0), got " + ToString());
}

std::string Shard::ToString() const { return std::to_string(index) + "/" + std::to_string(count); }

Shard ParseShard(const std::string& text, const std::string& where) {
  if (text.empty()) return Shard();
  const size_t slash = text.find('/');
  Shard shard;
  const bool parsed = slash != std::string::npos &&
                      internal::ParseInt(text.substr(0, slash), &shard.index) &&
                      internal::ParseInt(text.substr(slash + 1), &shard.count);
  Require(parsed && shard.count >= 1 && shard.index >= 0 && shard.index < shard.count, where,
          "expected I/N with 0 <= I < N (shards are numbered from 0, e.g. 0/4 to 3/4), got '" +
              text + "'");
  return shard;
}

FrameRange ShardOf(const FrameRange& range, const Shard& shard) {
  shard.Check();
  const long size = range.size();
  const long base = size / shard.count, extra = size % shard.count;
  // Part i starts after i parts of `base` frames and min(i, extra) extra frames.
  const auto start_of = [&](long part) {
    return range.begin + part * base + std::min(part, extra);
  };
  return {static_cast<int>(start_of(shard.index)), static_cast<int>(start_of(shard.index + 1))};
}

}  // namespace finecap
