// keepOneRunHeap (apps/common/one_run_heap.h): the allocator settings pose_estimation_3d2d makes
// for its one pair. Each TEST runs in a process of its own (one ctest entry each), so the
// settings do not reach other tests. Checked by counting the page faults a touch costs.
#include "one_run_heap.h"

#include <gtest/gtest.h>
#include <sys/resource.h>

#include <cstdlib>
#include <cstring>
#include <thread>

namespace {

constexpr std::size_t kBlock = 8u << 20;  // a pair's images and ORB pyramids, about
constexpr long kPages = kBlock / 4096;

long minorFaults() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_minflt;
}

// Page faults while a new block of kBlock bytes is allocated, written and freed.
long faultsToUseABlock() {
  const long before = minorFaults();
  char* p = static_cast<char*>(std::malloc(kBlock));
  std::memset(p, 1, kBlock);
  asm volatile("" : : "r"(p) : "memory");  // the writes are used: not optimised away with p
  const long faults = minorFaults() - before;
  std::free(p);
  return faults;
}

// Under AddressSanitizer malloc is its allocator, which keeps freed blocks in quarantine and
// hands out fresh memory: glibc's settings cannot apply there.
#if defined(__SANITIZE_ADDRESS__)
#define SKIP_WITHOUT_GLIBC_MALLOC() GTEST_SKIP() << "AddressSanitizer replaces glibc's malloc"
#else
#define SKIP_WITHOUT_GLIBC_MALLOC() (void)0
#endif

// glibc's default returns a block this size to the system when it is freed (or trims it from
// the heap's top), so the next stage faults every page in again: ~2048 faults a block.
TEST(OneRunHeap, AFreedBlockIsReusedWithoutFaults) {
  SKIP_WITHOUT_GLIBC_MALLOC();
  ASSERT_TRUE(pnpba::keepOneRunHeap());
  faultsToUseABlock();
  EXPECT_LT(faultsToUseABlock(), kPages / 32);
}

// TBB's workers allocate the second image's pyramids, from arenas of their own: the settings
// keep those too.
TEST(OneRunHeap, AWorkerThreadsFreedBlockIsReusedWithoutFaults) {
  SKIP_WITHOUT_GLIBC_MALLOC();
  ASSERT_TRUE(pnpba::keepOneRunHeap());
  long faults = -1;
  std::thread worker([&] {
    faultsToUseABlock();
    faults = faultsToUseABlock();
  });
  worker.join();
  EXPECT_LT(faults, kPages / 32);
}

}  // namespace
