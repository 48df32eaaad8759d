// Parsing of comma-separated numeric option values ("520.9,521,325.1,249.7") for the CLIs.
#pragma once

#include <string>
#include <vector>

namespace pnpba {

// Exactly n finite numbers; throws Error "<option>: <problem>".
std::vector<double> parseNumberList(const std::string& text, size_t n, const std::string& option);

}  // namespace pnpba
