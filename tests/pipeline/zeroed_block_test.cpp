// ZeroedBlock (pipeline/src/zeroed_block.h): every byte zero without having been written, the
// alignment it promises, and ownership that moves.
#include "zeroed_block.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <utility>

namespace pnpba {
namespace {

bool allZero(const void* data, size_t bytes) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < bytes; ++i) {
    if (p[i] != 0) return false;
  }
  return true;
}

TEST(ZeroedBlock, IsZeroAlignedAndWritableAtEverySize) {
  for (size_t bytes : {size_t{1}, size_t{4096}, size_t{3} << 20, size_t{12} << 20}) {
    SCOPED_TRACE(bytes);
    ZeroedBlock block(bytes);
    ASSERT_NE(block.data(), nullptr);
    const auto address = reinterpret_cast<uintptr_t>(block.data());
    EXPECT_EQ(address % 64, 0u);
    if (bytes >= (size_t{2} << 20)) {
      EXPECT_EQ(address % (size_t{2} << 20), 0u);
    }
    EXPECT_TRUE(allZero(block.data(), bytes));
    std::memset(block.data(), 0xAB, bytes);  // every byte is ours
    EXPECT_EQ(static_cast<unsigned char*>(block.data())[bytes - 1], 0xAB);
  }
  EXPECT_EQ(ZeroedBlock(0).data(), nullptr);
}

TEST(ZeroedBlock, MovesItsMemoryAndLeavesTheOtherEmpty) {
  ZeroedBlock a(size_t{3} << 20);
  static_cast<unsigned char*>(a.data())[5] = 7;
  void* const memory = a.data();
  ZeroedBlock b(std::move(a));
  EXPECT_EQ(a.data(), nullptr);
  EXPECT_EQ(b.data(), memory);
  ZeroedBlock c(4096);
  c = std::move(b);  // c's own block is released
  EXPECT_EQ(c.data(), memory);
  EXPECT_EQ(static_cast<unsigned char*>(c.data())[5], 7);
}

}  // namespace
}  // namespace pnpba
