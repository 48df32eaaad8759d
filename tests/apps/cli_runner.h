// Runs a CLI as a user would and captures exit code, stdout and stderr (tests only).
#pragma once

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "scratch_dir.h"

namespace pnpba::test {

struct CliRun {
  int exit_code;
  std::string out, err;
};

inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

inline CliRun runCli(const std::string& program, const std::string& args) {
  // In the process's own scratch folder (ctest -j runs tests of one binary in parallel
  // processes), and gone once read.
  const auto out = scratchPath("cli_out.txt"), err = scratchPath("cli_err.txt");
  const std::string cmd = program + " " + args + " >" + out.string() + " 2>" + err.string();
  const int status = std::system(cmd.c_str());
  CliRun run{WEXITSTATUS(status), slurp(out), slurp(err)};
  std::filesystem::remove(out);
  std::filesystem::remove(err);
  return run;
}

}  // namespace pnpba::test
