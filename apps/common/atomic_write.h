// Writes an output file so that a reader never sees it half-written: the content goes to a
// temporary file beside the target, which is renamed over the target only when complete.
#pragma once

#include <functional>
#include <ostream>
#include <string>

namespace pnpba {

// Calls write(stream) on a temporary file, then renames it to `path`. Throws pnpba::Error
// "<path>: <problem>" (and removes the temporary) if anything fails, including write throwing.
void writeFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write);

}  // namespace pnpba
