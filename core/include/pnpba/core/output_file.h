// Writing an output file without ever damaging what the path points at (DESIGN.md section 5):
//   - a regular file or a new path: written to a temporary file in the same folder, every
//     write, the fsync and the close checked, then renamed over the target; on any error the
//     temporary is removed and the previous file is left untouched;
//   - a symbolic link: followed (also when dangling) and its target treated so; the link
//     stays a link;
//   - anything else (character device such as /dev/stdout or /dev/full, FIFO, socket): written
//     straight into, every write checked; never renamed over, never unlinked;
//   - a folder, or a target whose folder is missing or not writable: an error.
// Errors are pnpba::Error "<path>: <reason>" with the OS's reason (strerror).
#pragma once

#include <functional>
#include <initializer_list>
#include <ostream>
#include <string>

namespace pnpba {

// Throws Error now if `path` can be known not to be writable (a folder, a missing or read-only
// folder): call it before long work so that nothing is computed for nothing.
void checkOutputPath(const std::string& path);

// Calls write(stream) to produce the content, then stores it at `path` by the rules above.
// Throws Error (and leaves the target as it was) on any failure, including write throwing.
void writeOutputFile(const std::string& path, const std::function<void(std::ostream&)>& write);

// True when `path` names the file this process's standard output is (e.g. /dev/stdout, or a
// path the shell redirected stdout to) or is "-": a CLI then prints its human text to stderr.
bool isStandardOutput(const std::string& path);
// True when any of `paths` is standard output (empty paths are skipped).
bool anyIsStandardOutput(std::initializer_list<std::string> paths);

}  // namespace pnpba
