// A folder of the test process's own for the files its tests write (tests only).
//
// Created under the system's temporary folder on first use, with a name no other process has
// (mkdtemp), and removed with everything in it when the process ends: two test runs at once, or
// two users on one machine, never read or overwrite each other's files, and none are left behind.
#pragma once

#include <stdlib.h>

#include <filesystem>
#include <stdexcept>
#include <string>
#include <system_error>

namespace pnpba::test {

class ScratchDir {
 public:
  ScratchDir() {
    std::string pattern = (std::filesystem::temp_directory_path() / "pnpba_test_XXXXXX").string();
    if (::mkdtemp(pattern.data()) == nullptr) {
      throw std::runtime_error("cannot create a scratch folder from " + pattern);
    }
    path_ = pattern;
  }
  ~ScratchDir() {
    std::error_code ignored;  // a test may have left a folder unreadable: take what can go
    std::filesystem::permissions(path_, std::filesystem::perms::owner_all, ignored);
    std::filesystem::remove_all(path_, ignored);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;

  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

// The process's scratch folder, created on the first call.
inline const std::filesystem::path& scratchDir() {
  static const ScratchDir dir;
  return dir.path();
}

// `name` inside the process's scratch folder.
inline std::filesystem::path scratchPath(const std::string& name) { return scratchDir() / name; }

}  // namespace pnpba::test
