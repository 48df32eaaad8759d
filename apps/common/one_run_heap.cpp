#include "one_run_heap.h"

#include <cstdlib>  // defines __GLIBC__ where the C library is glibc

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace pnpba {

bool keepOneRunHeap() {
#if defined(__GLIBC__)
  constexpr int kMiB = 1 << 20;
  // Measured through the CLI (bench/cli_pair_bench.py, docs/benchmarks.md) and not kept: one
  // arena for every thread (the depth path's parallel loops then waited on its lock). The heap on
  // transparent huge pages is the launcher's to ask for (apps/common/tool_launcher.cpp: glibc
  // reads it at start only).
  bool ok = mallopt(M_MMAP_THRESHOLD, 32 * kMiB) == 1;  // glibc's largest on 64-bit systems
  ok = mallopt(M_TRIM_THRESHOLD, 1024 * kMiB) == 1 && ok;
  ok = mallopt(M_TOP_PAD, 24 * kMiB) == 1 && ok;
  return ok;
#else
  return true;
#endif
}

}  // namespace pnpba
