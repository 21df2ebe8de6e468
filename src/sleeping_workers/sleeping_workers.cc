// Makes libgomp's workers sleep between parallel loops (OMP_WAIT_POLICY=passive) unless the caller
// chose a policy. After each loop libgomp's workers spin, by default, waiting for the next one;
// between the loops Ceres runs its own threads and the frame reader prepares the next frame, and a
// spinning worker takes a core from them.
//
// libgomp reads the policy once, from the environment, as it initialises: before main() and
// before the executable's own constructors. This library's constructor runs before libgomp's
// because the executable names it after libgomp among the libraries it needs, and the dynamic
// loader initialises libraries that do not depend on one another in the reverse of that order
// (CMakeLists.txt links it so; the CLI test reads the policy libgomp took with
// OMP_DISPLAY_ENV). The executable's .preinit_array is too early instead: glibc's own
// initialisation, which comes after it, resets the environment to the one the process started
// with.
#include <cstdlib>

namespace {

bool set_by_finecap = false;

__attribute__((constructor)) void PreferSleepingWorkers() {
  if (std::getenv("OMP_WAIT_POLICY") != nullptr || std::getenv("GOMP_SPINCOUNT") != nullptr) return;
  set_by_finecap = setenv("OMP_WAIT_POLICY", "passive", 1) == 0;
}

}  // namespace

namespace finecap {

// Whether the constructor above set the policy (false when the caller had set one). A symbol the
// executable uses, so that the linker keeps the library among the ones it needs.
__attribute__((visibility("default"))) bool SleepingWorkersSetByFinecap() { return set_by_finecap; }

}  // namespace finecap
