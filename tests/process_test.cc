#include "finecap/util/process.h"

#include <cstdint>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "finecap/util/error.h"

namespace finecap {
namespace {

// The VmFlags of the mapping of /proc/self/smaps that holds `address` ("" when none does).
std::string FlagsOfMappingAt(const void* address) {
  const auto at = reinterpret_cast<std::uintptr_t>(address);
  std::ifstream smaps("/proc/self/smaps");
  bool inside = false;
  for (std::string line; std::getline(smaps, line);) {
    std::uintptr_t begin = 0, end = 0;
    char dash = 0;
    std::istringstream range(line);
    if (range >> std::hex >> begin >> dash >> end && dash == '-') {
      inside = begin <= at && at < end;
    } else if (inside && line.rfind("VmFlags:", 0) == 0) {
      return line;
    }
  }
  return "";
}

bool KernelOffersHugePages() {
  std::ifstream mode("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string text;
  std::getline(mode, text);
  return !text.empty() && text.find("[never]") == std::string::npos;
}

// A block allocated afterwards, large as a frame's tables, lies in memory advised for huge pages.
TEST(BackHeapWithHugePagesTest, LaterBlocksLieInHugePageMemory) {
#if defined(__SANITIZE_ADDRESS__)
  EXPECT_FALSE(BackHeapWithHugePages(64 << 20));  // The sanitizer's allocator is not glibc's.
#else
  if (!KernelOffersHugePages()) GTEST_SKIP() << "transparent huge pages are off";
  ASSERT_TRUE(BackHeapWithHugePages(64 << 20));
  const auto block = std::make_unique<char[]>(16 << 20);
  EXPECT_NE(FlagsOfMappingAt(block.get()).find(" hg"), std::string::npos)
      << FlagsOfMappingAt(block.get());
#endif
}

TEST(BackHeapWithHugePagesTest, NothingToReserveChangesNothing) {
  EXPECT_FALSE(BackHeapWithHugePages(0));
  EXPECT_FALSE(ApplyProcessOptions({.one_malloc_arena = false, .huge_page_heap_mb = 0}));
}

TEST(ProcessOptionsTest, RefusesAReservationOutOfRange) {
  for (int megabytes : {-1, 2048}) {
    ProcessOptions options;
    options.huge_page_heap_mb = megabytes;
    EXPECT_THROW(options.Check(), Error) << megabytes;
  }
  EXPECT_NO_THROW(ProcessOptions().Check());
}

}  // namespace
}  // namespace finecap
