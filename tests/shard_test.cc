// Sharding a frame range: contiguous near-equal parts that cover it exactly once, and "I/N" text
// validated with errors that name where it came from.
#include "finecap/refine/shard.h"

#include <gtest/gtest.h>

#include "finecap/config/config.h"
#include "test_util.h"

namespace finecap {
namespace {

using testing_util::ExpectErrorMentions;

TEST(ShardTest, TenFramesInThreePartsGiveFourThreeThree) {
  const FrameRange range{0, 10};
  EXPECT_EQ(ShardOf(range, {0, 3}).begin, 0);
  EXPECT_EQ(ShardOf(range, {0, 3}).end, 4);
  EXPECT_EQ(ShardOf(range, {1, 3}).begin, 4);
  EXPECT_EQ(ShardOf(range, {1, 3}).end, 7);
  EXPECT_EQ(ShardOf(range, {2, 3}).begin, 7);
  EXPECT_EQ(ShardOf(range, {2, 3}).end, 10);
}

// Every split of every small range: the parts follow each other from begin to end, each frame in
// exactly one, sizes floor(n/N) or ceil(n/N) with the larger ones first.
TEST(ShardTest, PartsCoverTheRangeOnceWithSizesDifferingByAtMostOne) {
  for (int begin = 0; begin < 3; ++begin) {
    for (int size = 0; size <= 13; ++size) {
      for (int count = 1; count <= 6; ++count) {
        int expected_begin = begin;
        for (int index = 0; index < count; ++index) {
          const FrameRange part = ShardOf({begin, begin + size}, {index, count});
          const int expected_size = size / count + (index < size % count ? 1 : 0);
          EXPECT_EQ(part.begin, expected_begin)
              << begin << "+" << size << " " << index << "/" << count;
          EXPECT_EQ(part.size(), expected_size)
              << begin << "+" << size << " " << index << "/" << count;
          expected_begin = part.end;
        }
        EXPECT_EQ(expected_begin, begin + size);
      }
    }
  }
}

TEST(ShardTest, ParsesIndexOverCount) {
  const Shard shard = ParseShard("3/4", "--shard");
  EXPECT_EQ(shard.index, 3);
  EXPECT_EQ(shard.count, 4);
  EXPECT_EQ(shard.ToString(), "3/4");
  EXPECT_EQ(ParseShard("", "--shard").count, 1);
}

TEST(ShardTest, RefusesIndicesOutsideTheCountAndMalformedText) {
  for (const char* text : {"4/4", "1/0", "-1/3", "2", "a/b", "1/2/3", "/2", "1/"}) {
    ExpectErrorMentions([&] { ParseShard(text, "--shard"); },
                        {"--shard", std::string("'") + text + "'", "0 <= I < N"});
  }
  ExpectErrorMentions([] { ShardOf({0, 5}, {2, 2}); }, {"shard", "2/2"});
}

TEST(ShardTest, TheFlagOverridesTheKeyAndAnErrorNamesTheFlag) {
  const Config config = LoadConfig("", {{"runtime.shard", "1/3", "--shard"}});
  EXPECT_EQ(config.runtime.shard.index, 1);
  EXPECT_EQ(config.runtime.shard.count, 3);
  ExpectErrorMentions(
      [] {
        LoadConfig("", {{"runtime.shard", "4/4", "--shard"}});
      },
      {"--shard", "runtime.shard", "'4/4'"});
}

}  // namespace
}  // namespace finecap
