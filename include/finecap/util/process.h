// The settings the finecap executable makes for its whole process, in one place. Each changes how
// the process as a whole uses memory or cores, so only the executable makes them (tools/finecap.cc,
// first thing in main(), before any thread starts), each can be turned off there
// (`finecap --help`: --one_malloc_arena, --huge_page_heap_mb; OMP_WAIT_POLICY in the environment),
// and a program that uses the library makes its own choices. bench/process_settings.sh measures
// what each is worth against the defaults of glibc and libgomp; the figures are in
// docs/measurements.md ("Process-wide settings").
//
//   * One malloc arena. glibc gives each thread that allocates while another holds the lock an
//     arena of its own, up to eight per core, and memory freed into an arena stays there for that
//     arena's next allocations. finecap's threads (OpenMP's workers, Ceres', the frame reader)
//     each allocate a frame's buffers in turn, so every arena grows to its own high-water mark.
//   * The heap on huge pages. A run touches its peak memory once, page by page, in its first
//     frames, and on virtual machines a page fault costs ~12 us. The heap reserves address space
//     at its end (glibc's main arena, grown through the program break) and asks the kernel to back
//     it with transparent huge pages (madvise MADV_HUGEPAGE, which the kernel's default "madvise"
//     mode honours), so that a fault maps 2 MB at once; blocks of up to 32 MB are taken from the
//     heap instead of separate mappings (M_MMAP_THRESHOLD), and the heap's free top is kept
//     instead of being returned and faulted in again (M_TRIM_THRESHOLD). Only address space is
//     reserved: resident memory grows as pages are touched. Pages touched once stay resident, so
//     the peak resident memory of a long run can step up by a 2 MB page when a frame first reaches
//     a new one (FrameStats::heap_in_use_mb tells such steps from growth).
//   * OpenMP's workers sleep between parallel loops (OMP_WAIT_POLICY=passive) unless the caller
//     set OMP_WAIT_POLICY or GOMP_SPINCOUNT. After each loop libgomp's workers spin, by default,
//     waiting for the next; between the loops Ceres runs its own threads and the frame reader
//     prepares the next frame, and a spinning worker takes a core from them. libgomp reads the
//     policy once, as it loads, before main(): a library of its own sets it from its constructor
//     (src/sleeping_workers/sleeping_workers.cc, which says why it runs before libgomp's), and a
//     command-line test checks the policy libgomp took.
#ifndef FINECAP_UTIL_PROCESS_H_
#define FINECAP_UTIL_PROCESS_H_

namespace finecap {

struct ProcessOptions {
  // One malloc arena for every thread (glibc's M_ARENA_MAX 1).
  bool one_malloc_arena = true;
  // Address space reserved at the heap's end and backed by huge pages, MB; 0: none (glibc's own
  // thresholds and 4 KB pages). At most 2047 (glibc takes the reservation as an int of bytes).
  int huge_page_heap_mb = 1024;

  // Throws Error naming the option whose value is out of range.
  void Check() const;
};

// Makes the settings of `options`. Call it once, before any thread starts. Where the program break
// cannot grow, the kernel has no huge pages, or a sanitizer replaces malloc, the huge-page heap
// changes nothing but the thresholds. Returns whether the huge-page advice was taken.
bool ApplyProcessOptions(const ProcessOptions& options);

// The parts of ApplyProcessOptions, for tests.
void UseOneMallocArena();
bool BackHeapWithHugePages(int reserve_bytes);

// Whether OMP_WAIT_POLICY=passive was set for this process (false when the caller had set a
// policy).
bool SleepingWorkersSetByFinecap();

}  // namespace finecap

#endif  // FINECAP_UTIL_PROCESS_H_
