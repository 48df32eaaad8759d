// A bench's main(): what its body throws at a bad value it meets (a file, a name, a number)
// becomes one line naming the bench, and exit 2, instead of a crash.
#pragma once

#include <cstdio>
#include <exception>

namespace pnpba::bench {

inline int guardedMain(const char* name, int (*body)(int, char**), int argc, char** argv) {
  try {
    return body(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", name, e.what());
    return 2;
  }
}

}  // namespace pnpba::bench
