#include "finecap/io/vertex_mask.h"

#include <gtest/gtest.h>

#include "test_util.h"

namespace finecap {
namespace {

using testing_util::ExpectErrorMentions;
using testing_util::MakeTempDir;
using testing_util::WriteText;

TEST(VertexMaskTest, SortsAndDropsRepeatsAndComments) {
  const std::string path = MakeTempDir("mask") + "/mask.txt";
  WriteText(path, "# skirt vertices\n7 3\t12\n\n3  # again\n0\n11 # 99 is commented out\n");
  EXPECT_EQ(ReadVertexMask(path, 13), (std::vector<int>{0, 3, 7, 11, 12}));
}

TEST(VertexMaskTest, EmptyFileGivesEmptyMask) {
  const std::string path = MakeTempDir("mask") + "/mask.txt";
  WriteText(path, "# nothing\n");
  EXPECT_TRUE(ReadVertexMask(path, 5).empty());
}

TEST(VertexMaskTest, BadTokensAndIdsNameFileAndLine) {
  const std::string path = MakeTempDir("mask") + "/mask.txt";
  WriteText(path, "1 2\n3 x4\n");
  ExpectErrorMentions([&] { ReadVertexMask(path, 10); },
                      {path + " line 2", "'x4'", "not a vertex id"});
  WriteText(path, "1.5\n");
  ExpectErrorMentions([&] { ReadVertexMask(path, 10); }, {path + " line 1", "'1.5'"});
  WriteText(path, "1\n2\n\n10\n");
  ExpectErrorMentions([&] { ReadVertexMask(path, 10); },
                      {path + " line 4", "out of range", "10 vertices"});
  WriteText(path, "-1\n");
  ExpectErrorMentions([&] { ReadVertexMask(path, 10); }, {path + " line 1", "out of range"});
  ExpectErrorMentions([&] { ReadVertexMask(path + ".missing", 10); },
                      {"mask.txt.missing", "not found"});
}

}  // namespace
}  // namespace finecap
