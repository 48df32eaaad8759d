// A tool's executable: `TOOL --help` (or `-h`) alone prints the help the build kept from the
// tool's own parser (tool_help_writer.cpp); anything else opens the tool's plugin and runs it.
// The plugin links OpenCV or Ceres and their 20-40 shared libraries, whose mapping and relocation
// are most of a start-up where a page fault costs 10-25 us (a virtual machine's): a help that
// loads none of them starts in a few milliseconds (docs/benchmarks.md, "Start-up").
//
// PNPBA_TOOL_PARSE_HELP=1 skips the kept help (the tests compare the two).
//
// A tool that runs one job and exits (PNPBA_TOOL_HUGE_PAGE_HEAP: pose_estimation_3d2d,
// bundle_adjust_bal) asks glibc for its heap on transparent huge pages where the kernel gives them
// on request: one fault per 2 MB instead of per 4 KB page on the memory its work touches for the
// first time. glibc reads that setting (GLIBC_TUNABLES=glibc.malloc.hugetlb=1) only when a process
// starts, so the launcher starts itself again with it, once, before it loads anything. A
// GLIBC_TUNABLES that already names glibc.malloc.hugetlb (=0 turns it off) is left as it is.
#include <sys/auxv.h>
#include <unistd.h>

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

#ifdef PNPBA_TOOL_HUGE_PAGE_HEAP
constexpr bool kHugePageHeap = true;
#else
constexpr bool kHugePageHeap = false;
#endif

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

// True where transparent huge pages are given to memory that asks for them and only there
// ("always" gives them to the heap already, "never" to nothing).
bool hugePagesOnRequest() {
  std::FILE* mode = std::fopen("/sys/kernel/mm/transparent_hugepage/enabled", "r");
  if (mode == nullptr) return false;
  char line[128] = {};
  const bool read = std::fgets(line, sizeof line, mode) != nullptr;
  std::fclose(mode);
  return read && std::strstr(line, "[madvise]") != nullptr;
}

// Starts this program again with glibc's heap on huge pages, unless the environment already
// says how; returns only where it did not (then the run goes on as it is).
void restartOnHugePageHeap(char** argv) {
  constexpr const char* kName = "glibc.malloc.hugetlb";
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  if (tunables != nullptr && std::strstr(tunables, kName) != nullptr) return;
  // A set-user-ID run drops GLIBC_TUNABLES: it would start again and again.
  if (getauxval(AT_SECURE) != 0 || !hugePagesOnRequest()) return;
  const bool had_tunables = tunables != nullptr;
  const std::string before = had_tunables ? tunables : "";
  const std::string value =
      (before.empty() ? std::string() : before + ":") + std::string(kName) + "=1";
  if (setenv("GLIBC_TUNABLES", value.c_str(), 1) != 0) return;
  execv("/proc/self/exe", argv);
  // Not restarted (no /proc): the same run on the ordinary heap, the environment as it was.
  if (had_tunables) {
    setenv("GLIBC_TUNABLES", before.c_str(), 1);
  } else {
    unsetenv("GLIBC_TUNABLES");
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (asksOnlyForHelp(argc, argv)) return printKeptHelp(argv[0]);
  if (kHugePageHeap) restartOnHugePageHeap(argv);
  try {
    using ToolMain = int(int, char**);
    ToolMain* tool_main = pnpba::pluginFunction<ToolMain>(PNPBA_TOOL_PLUGIN, "pnpba_tool_main");
    return tool_main(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", argv[0], e.what());
    return 2;
  }
}
