#include "finecap/util/threads.h"

#include <omp.h>

#include <algorithm>

#include "finecap/util/error.h"

namespace finecap {

void SetWorkerThreads(int threads) {
  Require(threads >= 0, "threads", "must be non-negative");
  // OpenMP's own default, remembered before anything changes it.
  static const int default_threads = omp_get_max_threads();
  omp_set_num_threads(threads > 0 ? threads : default_threads);
}

std::vector<std::exception_ptr> ParallelForKeepingFailures(int count,
                                                           const std::function<void(int)>& task) {
  std::vector<std::exception_ptr> failures(std::max(count, 0));
#pragma omp parallel for schedule(dynamic, 1)
  for (int i = 0; i < count; ++i) {
    try {
      task(i);
    } catch (...) {
      failures[i] = std::current_exception();
    }
  }
  return failures;
}

void ParallelFor(int count, const std::function<void(int)>& task) {
  for (const std::exception_ptr& failure : ParallelForKeepingFailures(count, task)) {
    if (failure) std::rethrow_exception(failure);
  }
}

}  // namespace finecap
