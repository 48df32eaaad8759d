// Freed heap memory kept in the process, so that a loop of estimates reuses warm pages.
//
// A pose estimate allocates and frees tens of MB (point clouds and their neighbour lists, dense
// residuals, image pyramids). glibc's malloc maps a block of more than 128 KiB on its own and
// unmaps it when freed (M_MMAP_THRESHOLD), and trims the free top of a heap back to 128 KiB
// (M_TOP_PAD), so the next estimate faults the same pages in again, each one zeroed by the
// kernel. On a virtual machine a fault is dear: on the real texture-poor pairs
// the faults were an eighth of the samples, and keeping the pages cut the rendered rooms' p95 by
// a quarter to a half (docs/benchmarks.md, "Freed memory kept for the next pair"). With blocks up
// to the threshold below taken from the heaps, and that much kept free at the top of each heap,
// the next estimate reuses warm pages instead.
//
// The setting is the process's, not a call's, so it is made once: by the first pose estimate
// (estimateTwoView, describeFrame) unless the process chose before, in its environment or by a
// call below. Nothing computed depends on it; only which pages the allocator hands out.
#pragma once

#include <cstddef>

namespace pnpba {

// What the first estimate keeps: a 640 x 480 pair's depth path works in 10-20 MB. 32 MiB is also
// the largest mmap threshold glibc takes.
constexpr std::size_t kDefaultRetainedHeapBytes = std::size_t{32} << 20;

// For the whole process, now: blocks of up to `bytes` (at most 32 MiB) from the heaps, and
// `bytes` kept free at the top of each heap (glibc's M_MMAP_THRESHOLD and M_TOP_PAD). Marks the
// choice made, so that no estimate changes it later. Returns false where the C library is not
// glibc or refuses a value; the allocator then works as before.
bool retainFreedHeapMemory(std::size_t bytes);

// retainFreedHeapMemory(kDefaultRetainedHeapBytes), once per process, unless the choice is made
// already: by a call above, or in the environment, which glibc read at start (see below).
// Thread-safe; a few nanoseconds after the first.
void retainFreedHeapMemoryOnce();

// Whether this process's choice is made (by either call above, or found in its environment).
bool heapRetentionChosen();

// Whether an environment with these values (null: unset) tuned the heap itself: any of
// MALLOC_TOP_PAD_, MALLOC_MMAP_THRESHOLD_, MALLOC_TRIM_THRESHOLD_, or glibc.malloc.top_pad,
// .mmap_threshold or .trim_threshold in GLIBC_TUNABLES.
struct HeapEnvironment {
  const char* malloc_top_pad = nullptr;
  const char* malloc_mmap_threshold = nullptr;
  const char* malloc_trim_threshold = nullptr;
  const char* glibc_tunables = nullptr;
};
bool environmentTunesHeap(const HeapEnvironment& environment);

}  // namespace pnpba
