// Counting the page faults a piece of work takes: whether freed memory came back warm.
#pragma once

#include <sys/resource.h>

#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

namespace pnpba {
namespace test {

// Minor faults (pages the kernel handed in) the calling thread took while work() ran.
template <typename Work>
long minorFaultsDuring(Work work) {
  rusage before{}, after{};
  getrusage(RUSAGE_THREAD, &before);
  work();
  getrusage(RUSAGE_THREAD, &after);
  return after.ru_minflt - before.ru_minflt;
}

// Whether the kernel backs every anonymous mapping with huge pages where it can
// (transparent_hugepage "[always]"): then a heap faults in 2 MiB at a time, and a count of
// faults no longer tells warm memory from cold.
inline bool hugePagesAlways() {
  std::ifstream in("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string line;
  std::getline(in, line);
  return line.find("[always]") != std::string::npos;
}

// What an estimate's scratch memory does: `blocks` blocks of `block_bytes` (below malloc's
// mmap threshold, so from the heap), every byte written, then freed last first.
inline void allocateWriteFree(int blocks, std::size_t block_bytes) {
  std::vector<void*> taken;
  for (int i = 0; i < blocks; ++i) {
    void* p = std::malloc(block_bytes);
    std::memset(p, i, block_bytes);
    asm volatile("" : : "r"(p) : "memory");  // the writes are kept
    taken.push_back(p);
  }
  for (auto it = taken.rbegin(); it != taken.rend(); ++it) std::free(*it);
}

}  // namespace test
}  // namespace pnpba
