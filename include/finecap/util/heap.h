// How finecap's heap takes its memory from the system.
#ifndef FINECAP_UTIL_HEAP_H_
#define FINECAP_UTIL_HEAP_H_

namespace finecap {

// A run touches its peak memory (~200 MB on synth_skirt) once, page by page, in its first frames,
// and on the virtual machines finecap is measured on a page fault costs ~12 us: the ~45,000
// faults of 4 KB pages took ~0.5 s of a 10-frame run's CPU, most of it before the first frame's
// solve. This reserves `reserve_bytes` of address space at the heap's end (glibc's main arena,
// grown through the program break) and asks the kernel to back it with transparent huge pages
// (madvise MADV_HUGEPAGE, which the kernel's default "madvise" mode honours), so that a fault
// maps 2 MB at once; blocks of up to 32 MB are taken from the heap instead of separate mappings
// (M_MMAP_THRESHOLD), and the heap's free top is kept instead of being returned and faulted in
// again (M_TRIM_THRESHOLD). The reservation is address space only: resident memory grows as
// pages are touched, as before. Where the program break cannot grow, the kernel has no huge
// pages, or a sanitizer replaces malloc, this changes nothing but the thresholds. Call it first
// thing in main(), after UseOneMallocArena (threads.h), before any thread starts. Returns
// whether the huge-page advice was taken.
bool BackHeapWithHugePages(int reserve_bytes);

}  // namespace finecap

#endif  // FINECAP_UTIL_HEAP_H_
