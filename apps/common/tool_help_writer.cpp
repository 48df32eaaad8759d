// Build step of pnpba_tool (apps/CMakeLists.txt): runs a tool plugin's own parser with
// `--help` and keeps what it prints as a C++ string literal for the tool's launcher
// (tool_launcher.cpp), the program's name replaced by a marker the launcher fills in.
//
//   tool_help_writer PLUGIN OUTPUT.inc
#include <fcntl.h>
#include <unistd.h>

#include <cstdio>
#include <exception>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>

#include "pnpba/core/plugin.h"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::cerr << "usage: tool_help_writer PLUGIN OUTPUT.inc\n";
    return 2;
  }
  const std::string output = argv[2], captured = output + ".txt";
  try {
    using ToolMain = int(int, char**);
    ToolMain* tool_main = pnpba::pluginFunction<ToolMain>(argv[1], "pnpba_tool_main");
    // The parser writes to std::cout: standard output goes to a file while it runs.
    std::cout.flush();
    std::fflush(stdout);
    const int saved = dup(STDOUT_FILENO);
    const int file = open(captured.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (saved < 0 || file < 0) throw std::runtime_error("cannot open " + captured);
    dup2(file, STDOUT_FILENO);
    close(file);
    char program[] = "@PNPBA_PROGRAM@", help[] = "--help";
    char* args[] = {program, help, nullptr};
    const int status = tool_main(2, args);
    std::cout.flush();
    std::fflush(stdout);
    dup2(saved, STDOUT_FILENO);
    close(saved);
    std::ifstream in(captured);
    std::stringstream text;
    text << in.rdbuf();
    std::remove(captured.c_str());
    const std::string delimiter = "pnpbahelp";
    if (status != 0 || text.str().empty() ||
        text.str().find(")" + delimiter) != std::string::npos) {
      throw std::runtime_error(std::string(argv[1]) + ": --help gave exit status " +
                               std::to_string(status) + " and " +
                               std::to_string(text.str().size()) + " bytes");
    }
    std::ofstream out(output);
    out << "R\"" << delimiter << "(" << text.str() << ")" << delimiter << "\"\n";
    if (!out.flush()) throw std::runtime_error("cannot write " + output);
  } catch (const std::exception& e) {
    std::cerr << "tool_help_writer: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
