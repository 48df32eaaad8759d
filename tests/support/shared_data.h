// Where tests find the shared real data (CMake cache variable PNPBA_SHARED_DATA), and the
// macro that skips a test, saying why, when that folder is absent.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

namespace pnpba::test {

inline std::string sharedData(const std::string& relative) {
  return std::string(PNPBA_SHARED_DATA) + "/" + relative;
}

}  // namespace pnpba::test

#define PNPBA_REQUIRE_SHARED_DATA()                                                 \
  do {                                                                              \
    if (!std::filesystem::is_directory(PNPBA_SHARED_DATA)) {                        \
      GTEST_SKIP() << "shared data folder " << PNPBA_SHARED_DATA                    \
                   << " is absent (set -DPNPBA_SHARED_DATA=<path to shared/data>)"; \
    }                                                                               \
  } while (0)
