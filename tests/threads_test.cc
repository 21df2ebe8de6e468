#include "finecap/util/threads.h"

#include <malloc.h>
#include <omp.h>

#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "finecap/util/error.h"
#include "finecap/util/process.h"

namespace finecap {
namespace {

// The number of threads an OpenMP parallel region started now runs with.
int ThreadsOfAParallelRegion() {
  int threads = 0;
#pragma omp parallel
  {
#pragma omp single
    threads = omp_get_num_threads();
  }
  return threads;
}

TEST(ParallelForTest, RunsEveryIndexOnce) {
  std::vector<int> runs(37, 0);
  ParallelFor(static_cast<int>(runs.size()), [&](int i) { ++runs[i]; });
  EXPECT_EQ(runs, std::vector<int>(runs.size(), 1));
  ParallelFor(0, [](int) { FAIL() << "no index to run"; });
}

TEST(ParallelForTest, KeepsEachFailureAtItsIndex) {
  std::vector<int> ran(8, 0);
  const std::vector<std::exception_ptr> failures = ParallelForKeepingFailures(8, [&](int i) {
    ran[i] = 1;
    if (i % 3 == 1) throw Error("camera " + std::to_string(i), "unreadable");
  });
  ASSERT_EQ(failures.size(), 8u);
  EXPECT_EQ(ran, std::vector<int>(8, 1));  // A failure does not stop the others.
  for (int i = 0; i < 8; ++i) EXPECT_EQ(failures[i] != nullptr, i % 3 == 1) << i;
}

TEST(ParallelForTest, RethrowsTheFailureOfTheLowestIndex) {
  // Whichever thread fails first, the error is the one a loop in order would meet first.
  for (int repeat = 0; repeat < 20; ++repeat) {
    try {
      ParallelFor(16, [](int i) {
        if (i >= 5) throw Error("camera " + std::to_string(i), "unreadable");
      });
      FAIL() << "nothing thrown";
    } catch (const Error& error) {
      EXPECT_NE(std::string(error.what()).find("camera 5:"), std::string::npos) << error.what();
    }
  }
}

TEST(SetWorkerThreadsTest, LimitsTheOpenMpStagesAndRestoresTheDefault) {
  const int default_threads = omp_get_max_threads();
  SetWorkerThreads(1);
  EXPECT_EQ(ThreadsOfAParallelRegion(), 1);
  SetWorkerThreads(3);
  EXPECT_EQ(ThreadsOfAParallelRegion(), 3);
  SetWorkerThreads(0);
  EXPECT_EQ(omp_get_max_threads(), default_threads);
}

TEST(SetWorkerThreadsTest, RefusesANegativeCount) { EXPECT_THROW(SetWorkerThreads(-1), Error); }

// The heaps glibc's malloc has now (malloc_info's <heap> elements).
int MallocHeaps() {
  char* text = nullptr;
  size_t size = 0;
  FILE* stream = open_memstream(&text, &size);
  malloc_info(0, stream);
  std::fclose(stream);
  const std::string info(text, size);
  std::free(text);
  int heaps = 0;
  for (size_t at = info.find("<heap nr="); at != std::string::npos;
       at = info.find("<heap nr=", at + 1)) {
    ++heaps;
  }
  return heaps;
}

// Threads that allocate at once all allocate from the one arena.
TEST(UseOneMallocArenaTest, ThreadsAllocatingAtOnceShareOneHeap) {
  UseOneMallocArena();
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([] {
      for (int i = 0; i < 2000; ++i) {
        std::vector<char> buffer(64 + i);
        buffer[0] = 1;
      }
    });
  }
  for (std::thread& thread : threads) thread.join();
  EXPECT_EQ(MallocHeaps(), 1);
}

}  // namespace
}  // namespace finecap
