#include "finecap/util/threads.h"

#include <omp.h>

#include "finecap/util/error.h"

namespace finecap {

void SetWorkerThreads(int threads) {
  Require(threads >= 0, "threads", "must be non-negative");
  // OpenMP's own default, remembered before anything changes it.
  static const int default_threads = omp_get_max_threads();
  omp_set_num_threads(threads > 0 ? threads : default_threads);
}

}  // namespace finecap
