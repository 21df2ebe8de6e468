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

// OpenMP's workers (libgomp's default) spin for a while after each parallel loop, waiting for the
// next. Between the loops Ceres runs its own threads and the frame reader reads and prepares the
// next frame, and a spinning worker takes a core from them. The finecap executable makes them
// sleep instead (OMP_WAIT_POLICY=passive) unless the caller set OMP_WAIT_POLICY or
// GOMP_SPINCOUNT: libgomp reads the policy once, as it loads, so a library of its own sets it
// from its constructor (src/sleeping_workers/sleeping_workers.cc). This says whether it did;
// only the executable links that library.
bool SleepingWorkersSetByFinecap();

// glibc gives each thread that allocates while another holds the lock an arena of its own, up to
// eight per core, and memory freed into an arena stays there for that arena's next allocations.
// finecap's threads (OpenMP's workers, Ceres', the frame reader) each allocate a frame's buffers
// in turn, so every arena grows to its own high-water mark: a synth_skirt run peaked 50 MB higher
// (270 against 217 MB) with no measurable gain in speed. This keeps one arena for the process.
// Call it first thing in main(), before any thread starts.
void UseOneMallocArena();

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
