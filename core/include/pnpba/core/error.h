// The one exception type of pnpba: thrown for bad input (malformed files, inconsistent graphs,
// invalid options). "Could not estimate" is not an exception: estimators return ok=false.
#pragma once

#include <stdexcept>
#include <string>

namespace pnpba {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& what) : std::runtime_error(what) {}
};

}  // namespace pnpba
