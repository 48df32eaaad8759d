// Runs a CLI as a user would and captures exit code, stdout and stderr (tests only).
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

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
  const auto dir = std::filesystem::temp_directory_path();
  // Per process: ctest -j runs tests of one binary in parallel processes.
  const std::string id = std::to_string(::getpid());
  const auto out = dir / ("pnpba_cli_out_" + id + ".txt"),
             err = dir / ("pnpba_cli_err_" + id + ".txt");
  const std::string cmd = program + " " + args + " >" + out.string() + " 2>" + err.string();
  const int status = std::system(cmd.c_str());
  return {WEXITSTATUS(status), slurp(out), slurp(err)};
}

}  // namespace pnpba::test
