// Memory that starts zeroed without being written: fresh anonymous pages, in 2 MB huge pages
// where the kernel grants them (madvise), so that a first touch faults 2 MB at once instead of
// 4 KB. A new process's first alignment touched most of a 12 MB surface cache a page at a time,
// and on this machine kind's virtual machines each such fault costs several microseconds.
#pragma once

#include <cstddef>

namespace pnpba {

class ZeroedBlock {
 public:
  ZeroedBlock() = default;
  explicit ZeroedBlock(size_t bytes);  // throws std::bad_alloc
  ~ZeroedBlock();
  ZeroedBlock(const ZeroedBlock&) = delete;
  ZeroedBlock& operator=(const ZeroedBlock&) = delete;
  ZeroedBlock(ZeroedBlock&& other) noexcept { *this = static_cast<ZeroedBlock&&>(other); }
  ZeroedBlock& operator=(ZeroedBlock&& other) noexcept;  // `other` is left empty

  // `bytes` zero bytes, 64-byte aligned (2 MB where huge pages were asked for); null when empty.
  void* data() const { return data_; }

 private:
  void* mapping_ = nullptr;
  size_t length_ = 0;
  void* data_ = nullptr;
};

}  // namespace pnpba
