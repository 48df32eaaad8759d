#include "zeroed_block.h"

#include <sys/mman.h>

#include <cstdint>
#include <new>
#include <utility>

namespace pnpba {

namespace {

constexpr size_t kHugePage = size_t{2} << 20;

}  // namespace

ZeroedBlock::ZeroedBlock(size_t bytes) {
  if (bytes == 0) return;
  // Below a huge page the padding would cost more than the faults it saves.
  const bool huge = bytes >= kHugePage;
  length_ = bytes + (huge ? kHugePage : 0);
  mapping_ = ::mmap(nullptr, length_, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (mapping_ == MAP_FAILED) {
    mapping_ = nullptr;
    length_ = 0;
    throw std::bad_alloc();
  }
  auto start = reinterpret_cast<uintptr_t>(mapping_);
  if (huge) {
    start = (start + kHugePage - 1) & ~(kHugePage - 1);
    // Advice only: where the kernel has no huge page, 4 KB pages serve as before.
    ::madvise(reinterpret_cast<void*>(start), (bytes + kHugePage - 1) & ~(kHugePage - 1),
              MADV_HUGEPAGE);
  }
  data_ = reinterpret_cast<void*>(start);
}

ZeroedBlock::~ZeroedBlock() {
  if (mapping_ != nullptr) ::munmap(mapping_, length_);
}

ZeroedBlock& ZeroedBlock::operator=(ZeroedBlock&& other) noexcept {
  if (this != &other) {
    if (mapping_ != nullptr) ::munmap(mapping_, length_);
    mapping_ = std::exchange(other.mapping_, nullptr);
    length_ = std::exchange(other.length_, 0);
    data_ = std::exchange(other.data_, nullptr);
  }
  return *this;
}

}  // namespace pnpba
