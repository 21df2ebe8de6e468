// How many threads finecap's parallel stages use. The solvers take their thread count as an
// option (SolverOptions::num_threads, for Ceres); the other stages (visibility, image Gaussians,
// pair lists, energy evaluation, rendering) are OpenMP loops, which this sets.
#ifndef FINECAP_UTIL_THREADS_H_
#define FINECAP_UTIL_THREADS_H_

#include <exception>
#include <functional>
#include <vector>

namespace finecap {

// Makes the OpenMP stages use `threads` threads from now on; 0 restores OpenMP's default as it
// was before the first call (all cores, or OMP_NUM_THREADS where set). Call it from the main
// thread, before a parallel stage: runtime.threads of a config.
void SetWorkerThreads(int threads);

// Runs task(i) for every i in [0, count) on the OpenMP threads, one index at a time (for a few
// long tasks, such as decoding or modelling each camera's image). An exception may not leave an
// OpenMP region, so each task's is kept: the result holds, per index, the exception its task
// threw, or null. The caller can then report the failures as a loop over the indices in order
// would have met them.
std::vector<std::exception_ptr> ParallelForKeepingFailures(int count,
                                                           const std::function<void(int)>& task);

// ParallelForKeepingFailures, then rethrows the failure of the lowest index, if any.
void ParallelFor(int count, const std::function<void(int)>& task);

}  // namespace finecap

#endif  // FINECAP_UTIL_THREADS_H_
