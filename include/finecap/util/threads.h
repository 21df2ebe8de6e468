// How many threads finecap's parallel stages use. The solvers take their thread count as an
// option (SolverOptions::num_threads, for Ceres); the other stages (visibility, image Gaussians,
// pair lists, energy evaluation, rendering) are OpenMP loops, which this sets.
#ifndef FINECAP_UTIL_THREADS_H_
#define FINECAP_UTIL_THREADS_H_

namespace finecap {

// Makes the OpenMP stages use `threads` threads from now on; 0 restores OpenMP's default as it
// was before the first call (all cores, or OMP_NUM_THREADS where set). Call it from the main
// thread, before a parallel stage: runtime.threads of a config.
void SetWorkerThreads(int threads);

}  // namespace finecap

#endif  // FINECAP_UTIL_THREADS_H_
