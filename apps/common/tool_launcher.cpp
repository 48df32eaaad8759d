// A tool's executable: `TOOL --help` (or `-h`) alone prints the help the build kept from the
// tool's own parser (tool_help_writer.cpp); anything else opens the tool's plugin and runs it.
// The plugin links OpenCV or Ceres and their 20-40 shared libraries, whose mapping and relocation
// are most of a start-up where a page fault costs 10-25 us (a virtual machine's): a help that
// loads none of them starts in a few milliseconds (docs/benchmarks.md, "Start-up").
//
// PNPBA_TOOL_PARSE_HELP=1 skips the kept help (the tests compare the two).
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <string>

#include "pnpba/core/plugin.h"

namespace {

const char kKeptHelp[] =
#include PNPBA_TOOL_HELP_FILE
    ;

// The parser names the program by argv[0]; the kept help has this in its place.
constexpr const char* kProgramMarker = "@PNPBA_PROGRAM@";

bool asksOnlyForHelp(int argc, char** argv) {
  if (argc != 2) return false;
  if (std::strcmp(argv[1], "--help") != 0 && std::strcmp(argv[1], "-h") != 0) return false;
  const char* parse = std::getenv("PNPBA_TOOL_PARSE_HELP");
  return parse == nullptr || std::strcmp(parse, "1") != 0;
}

int printKeptHelp(const char* program) {
  std::string help = kKeptHelp;
  const std::string marker = kProgramMarker;
  for (size_t at = help.find(marker); at != std::string::npos;
       at = help.find(marker, at + std::strlen(program))) {
    help.replace(at, marker.size(), program);
  }
  std::fwrite(help.data(), 1, help.size(), stdout);
  return 0;  // as the parser's help: a closed or full stdout is not the tool's error
}

}  // namespace

int main(int argc, char** argv) {
  if (asksOnlyForHelp(argc, argv)) return printKeptHelp(argv[0]);
  try {
    using ToolMain = int(int, char**);
    ToolMain* tool_main = pnpba::pluginFunction<ToolMain>(PNPBA_TOOL_PLUGIN, "pnpba_tool_main");
    return tool_main(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", argv[0], e.what());
    return 2;
  }
}
