// The fuzzers' one piece of glue: pnpba's readers take a path, so each input is handed to them
// as an in-memory file (memfd) reached through /proc/self/fd. A reader may throw pnpba::Error,
// which is its documented answer to bad input; anything else (another exception, a crash, a
// sanitizer report, a leak, a hang) is a finding.
#pragma once

#include <sys/mman.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "pnpba/core/error.h"

namespace pnpba::fuzz {

class MemoryFile {
 public:
  MemoryFile(const uint8_t* data, size_t size) : fd_(::memfd_create("pnpba-fuzz", MFD_CLOEXEC)) {
    if (fd_ < 0) std::abort();
    size_t done = 0;
    while (done < size) {
      const ssize_t n = ::write(fd_, data + done, size - done);
      if (n <= 0) std::abort();
      done += static_cast<size_t>(n);
    }
  }
  ~MemoryFile() { ::close(fd_); }
  MemoryFile(const MemoryFile&) = delete;
  MemoryFile& operator=(const MemoryFile&) = delete;
  std::string path() const { return "/proc/self/fd/" + std::to_string(fd_); }

 private:
  int fd_;
};

// Runs read(path) on the input; pnpba::Error is the expected way to refuse it.
template <class Reader>
int readAsFile(const uint8_t* data, size_t size, Reader read) {
  const MemoryFile file(data, size);
  try {
    read(file.path());
  } catch (const pnpba::Error&) {
  }
  return 0;
}

}  // namespace pnpba::fuzz
