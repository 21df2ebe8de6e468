#include "finecap/util/threads.h"

#include <omp.h>

#include <gtest/gtest.h>

#include "finecap/util/error.h"

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

}  // namespace
}  // namespace finecap
