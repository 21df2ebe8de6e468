// The memory a process may use: MemAvailable, a cgroup's limit, the smaller of the two.
#include "finecap/util/memory.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "test_util.h"

namespace finecap {
namespace {

namespace fs = std::filesystem;

constexpr char kMemInfo[] =
    "MemTotal:       32000000 kB\n"
    "MemFree:         1000000 kB\n"
    "MemAvailable:    4000000 kB\n"
    "Buffers:           10000 kB\n";

// Writes `text` at `root`/`path`, creating its folders.
void WriteAt(const fs::path& root, const std::string& path, const std::string& text) {
  const fs::path file = root / path;
  fs::create_directories(file.parent_path());
  std::ofstream(file) << text;
}

TEST(ParseMemAvailableTest, ReadsTheLineInKilobytes) {
  EXPECT_DOUBLE_EQ(ParseMemAvailableMegabytes(kMemInfo), 4000000 * 1024.0 / 1e6);
  EXPECT_LT(ParseMemAvailableMegabytes("MemTotal: 100 kB\n"), 0.0);
  EXPECT_LT(ParseMemAvailableMegabytes("MemAvailable: lots\n"), 0.0);
  EXPECT_LT(ParseMemAvailableMegabytes("MemAvailable: 100 MB\n"), 0.0);
  EXPECT_LT(ParseMemAvailableMegabytes(""), 0.0);
}

TEST(ParseCgroupLimitTest, BytesMaxAndV1sNoLimit) {
  EXPECT_DOUBLE_EQ(ParseCgroupLimitMegabytes("536870912\n"), 536.870912);
  EXPECT_TRUE(std::isinf(ParseCgroupLimitMegabytes("max\n")));
  EXPECT_TRUE(std::isinf(ParseCgroupLimitMegabytes("9223372036854771712\n")));
  EXPECT_LT(ParseCgroupLimitMegabytes("12abc\n"), 0.0);
  EXPECT_LT(ParseCgroupLimitMegabytes("-5\n"), 0.0);
  EXPECT_LT(ParseCgroupLimitMegabytes(""), 0.0);
}

TEST(ReadAvailableMemoryTest, MemAvailableWithoutACgroupLimit) {
  const fs::path root = testing_util::MakeTempDir("memory_meminfo");
  WriteAt(root, "proc/meminfo", kMemInfo);
  WriteAt(root, "sys/fs/cgroup/memory.max", "max\n");
  const AvailableMemory available = ReadAvailableMemory(root.string());
  EXPECT_DOUBLE_EQ(available.megabytes, 4096.0);
  EXPECT_EQ(available.source, "/proc/meminfo");
}

TEST(ReadAvailableMemoryTest, TheCgroupLimitWhenItIsSmaller) {
  const fs::path root = testing_util::MakeTempDir("memory_cgroup_v2");
  WriteAt(root, "proc/meminfo", kMemInfo);
  WriteAt(root, "proc/self/cgroup", "0::/jobs/run7\n");
  WriteAt(root, "sys/fs/cgroup/memory.max", "max\n");
  WriteAt(root, "sys/fs/cgroup/jobs/run7/memory.max", "1000000000\n");
  const AvailableMemory available = ReadAvailableMemory(root.string());
  EXPECT_DOUBLE_EQ(available.megabytes, 1000.0);
  EXPECT_EQ(available.source, "/sys/fs/cgroup/jobs/run7/memory.max");

  // A limit above what the machine has free: the machine's figure.
  WriteAt(root, "sys/fs/cgroup/jobs/run7/memory.max", "64000000000\n");
  EXPECT_EQ(ReadAvailableMemory(root.string()).source, "/proc/meminfo");
}

TEST(ReadAvailableMemoryTest, CgroupV1Limit) {
  const fs::path root = testing_util::MakeTempDir("memory_cgroup_v1");
  WriteAt(root, "proc/meminfo", kMemInfo);
  WriteAt(root, "sys/fs/cgroup/memory/memory.limit_in_bytes", "2000000000\n");
  const AvailableMemory available = ReadAvailableMemory(root.string());
  EXPECT_DOUBLE_EQ(available.megabytes, 2000.0);
  EXPECT_EQ(available.source, "/sys/fs/cgroup/memory/memory.limit_in_bytes");
}

TEST(ReadAvailableMemoryTest, NothingReadableIsNoLimit) {
  const fs::path root = testing_util::MakeTempDir("memory_nothing");
  const AvailableMemory available = ReadAvailableMemory(root.string());
  EXPECT_TRUE(std::isinf(available.megabytes));
  EXPECT_EQ(available.source, "");
}

// The live system always has a /proc/meminfo.
TEST(ReadAvailableMemoryTest, TheLiveSystemHasAFigure) {
  const AvailableMemory available = ReadAvailableMemory();
  EXPECT_GT(available.megabytes, 0.0);
  EXPECT_TRUE(std::isfinite(available.megabytes));
  EXPECT_FALSE(available.source.empty());
}

}  // namespace
}  // namespace finecap
