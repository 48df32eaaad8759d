#include "pnpba/core/heap_retention.h"

#include <algorithm>
#include <atomic>
#include <climits>
#include <cstdlib>
#include <cstring>
#include <mutex>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace pnpba {

namespace {

std::atomic<bool> g_chosen{false};
std::once_flag g_once;

}  // namespace

bool environmentTunesHeap(const HeapEnvironment& environment) {
  if (environment.malloc_top_pad || environment.malloc_mmap_threshold ||
      environment.malloc_trim_threshold) {
    return true;
  }
  const char* tunables = environment.glibc_tunables;
  if (tunables == nullptr) return false;
  for (const char* name :
       {"glibc.malloc.top_pad", "glibc.malloc.mmap_threshold", "glibc.malloc.trim_threshold"}) {
    if (std::strstr(tunables, name) != nullptr) return true;
  }
  return false;
}

bool retainFreedHeapMemory(std::size_t bytes) {
  g_chosen.store(true);
#if defined(__GLIBC__)
  if (bytes > static_cast<std::size_t>(INT_MAX)) return false;  // mallopt takes an int
  const int threshold = static_cast<int>(std::min(bytes, kDefaultRetainedHeapBytes));
  // The threshold first: setting either fixes it (glibc stops moving it with the blocks freed).
  return mallopt(M_MMAP_THRESHOLD, threshold) == 1 &&
         mallopt(M_TOP_PAD, static_cast<int>(bytes)) == 1;
#else
  (void)bytes;
  return false;
#endif
}

void retainFreedHeapMemoryOnce() {
  if (g_chosen.load(std::memory_order_relaxed)) return;
  std::call_once(g_once, [] {
    if (g_chosen.load()) return;
    const HeapEnvironment environment{
        std::getenv("MALLOC_TOP_PAD_"), std::getenv("MALLOC_MMAP_THRESHOLD_"),
        std::getenv("MALLOC_TRIM_THRESHOLD_"), std::getenv("GLIBC_TUNABLES")};
    if (environmentTunesHeap(environment)) {
      g_chosen.store(true);
      return;
    }
    retainFreedHeapMemory(kDefaultRetainedHeapBytes);
  });
}

bool heapRetentionChosen() { return g_chosen.load(); }

}  // namespace pnpba
