// Freed heap memory kept for the next estimate: with it, a second round of the same
// allocations takes (almost) no page faults, blocks of the heap's size and blocks glibc would
// map on their own alike; with glibc's 128 KiB the second round faults its pages in again. The
// environment's own tuning wins over the library's.
#include "pnpba/core/heap_retention.h"

#include <gtest/gtest.h>

#include "page_faults.h"

namespace pnpba {
namespace {

constexpr std::size_t kRoundBytes = 8 << 20;  // 2048 pages a round
constexpr long kPages = kRoundBytes / 4096;

long faultsOfASecondRound(std::size_t block_bytes) {
  const int blocks = static_cast<int>(kRoundBytes / block_bytes);
  test::allocateWriteFree(blocks, block_bytes);
  return test::minorFaultsDuring([&] { test::allocateWriteFree(blocks, block_bytes); });
}

#if defined(__GLIBC__) && !defined(__SANITIZE_ADDRESS__)
TEST(HeapRetention, FreedMemoryComesBackWarmWhenRetainedAndColdWithout) {
  for (const std::size_t block : {std::size_t{64} << 10, std::size_t{4} << 20}) {
    SCOPED_TRACE("blocks of " + std::to_string(block) + " bytes");
    ASSERT_TRUE(retainFreedHeapMemory(128 << 10));  // glibc's starting values
    const long cold = faultsOfASecondRound(block);
    // The measurement sees the pages come back cold (unless huge pages hide them).
    if (!test::hugePagesAlways()) EXPECT_GT(cold, kPages / 4) << "of " << kPages << " pages";
    ASSERT_TRUE(retainFreedHeapMemory(kDefaultRetainedHeapBytes));
    EXPECT_LT(faultsOfASecondRound(block), kPages / 20) << "of " << kPages << " pages";
  }
}
#endif

TEST(HeapRetention, TheEnvironmentsOwnTuningWins) {
  EXPECT_FALSE(environmentTunesHeap({}));
  EXPECT_FALSE(environmentTunesHeap({nullptr, nullptr, nullptr, "glibc.malloc.arena_max=2"}));
  EXPECT_TRUE(environmentTunesHeap({"1048576", nullptr, nullptr, nullptr}));
  EXPECT_TRUE(environmentTunesHeap({nullptr, "1048576", nullptr, nullptr}));
  EXPECT_TRUE(environmentTunesHeap({nullptr, nullptr, "0", nullptr}));
  for (const char* tunables :
       {"glibc.malloc.arena_max=2:glibc.malloc.top_pad=0", "glibc.malloc.mmap_threshold=131072",
        "glibc.malloc.trim_threshold=0:glibc.malloc.arena_max=2"}) {
    EXPECT_TRUE(environmentTunesHeap({nullptr, nullptr, nullptr, tunables})) << tunables;
  }
}

TEST(HeapRetention, MoreThanMalloptTakesIsRefused) {
#if defined(__GLIBC__)
  EXPECT_FALSE(retainFreedHeapMemory(std::size_t{1} << 40));
#endif
}

}  // namespace
}  // namespace pnpba
