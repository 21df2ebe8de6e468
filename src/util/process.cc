#include "finecap/util/process.h"

#include <malloc.h>
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>

#include "util/option_checks.h"

namespace finecap {
namespace {

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kMallocIsGlibcs = false;  // AddressSanitizer brings its own allocator.
#else
constexpr bool kMallocIsGlibcs = true;
#endif

// glibc's largest M_MMAP_THRESHOLD on 64-bit systems, and its default M_TOP_PAD.
constexpr int kLargestHeapBlock = 32 << 20;
constexpr int kDefaultTopPad = 128 << 10;

}  // namespace

void ProcessOptions::Check() const {
  internal::RequireFieldRange(huge_page_heap_mb, 0, 2047, "ProcessOptions::huge_page_heap_mb");
}

bool ApplyProcessOptions(const ProcessOptions& options) {
  options.Check();
  if (options.one_malloc_arena) UseOneMallocArena();
  return BackHeapWithHugePages(options.huge_page_heap_mb << 20);
}

void UseOneMallocArena() { mallopt(M_ARENA_MAX, 1); }

bool BackHeapWithHugePages(int reserve_bytes) {
  if (!kMallocIsGlibcs || reserve_bytes <= 0) return false;
  // Fixed thresholds also turn off glibc's own adjustment of them, which starts at 128 KB and
  // would map the first large blocks (a frame's images, tables) outside the heap.
  mallopt(M_MMAP_THRESHOLD, kLargestHeapBlock);
  mallopt(M_TRIM_THRESHOLD, static_cast<int>((1u << 31) - 1));
  const auto page = static_cast<std::uintptr_t>(sysconf(_SC_PAGESIZE));
  const auto before = reinterpret_cast<std::uintptr_t>(sbrk(0));
  // The heap's next growth takes `reserve_bytes` beyond what it needs, and a block larger than the
  // heap has free (but not so large that it would be mapped on its own) makes it grow now.
  mallopt(M_TOP_PAD, reserve_bytes);
  void* probe = std::malloc(kLargestHeapBlock / 2);
  mallopt(M_TOP_PAD, kDefaultTopPad);
  const auto after = reinterpret_cast<std::uintptr_t>(sbrk(0));
  bool advised = false;
  // The heap grew at its end (not elsewhere, by a separate mapping, where the break cannot move).
  if (probe != nullptr && before != static_cast<std::uintptr_t>(-1) && after > before &&
      after - before >= static_cast<std::uintptr_t>(reserve_bytes) / 2) {
    // From the heap's free top as it was, where the probe began: the blocks below it are in use.
    const std::uintptr_t begin =
        std::min(reinterpret_cast<std::uintptr_t>(probe), before) / page * page;
    advised = madvise(reinterpret_cast<void*>(begin), after - begin, MADV_HUGEPAGE) == 0;
  }
  std::free(probe);
  return advised;
}

}  // namespace finecap
