// Reading one number from a text token, the way every pnpba file reader and CLI does: the whole
// token must be a number, and the number must be finite. Each caller words its own error.
#pragma once

#include <cmath>
#include <cstdlib>
#include <string>

#include "pnpba/core/error.h"

namespace pnpba {

enum class NumberStatus { kOk, kNotANumber, kNotFinite };

inline NumberStatus parseNumber(const std::string& token, double* value) {
  char* end = nullptr;
  *value = std::strtod(token.c_str(), &end);
  if (token.empty() || end == token.c_str() || *end != '\0') return NumberStatus::kNotANumber;
  return std::isfinite(*value) ? NumberStatus::kOk : NumberStatus::kNotFinite;
}

// The text readers' common wording: throws Error "<where>'<token>' is not a number" or
// "<where>non-finite value '<token>'", where is "<file>:<line>: ".
inline double numberOrThrow(const std::string& token, const std::string& where) {
  double v = 0;
  switch (parseNumber(token, &v)) {
    case NumberStatus::kOk:
      return v;
    case NumberStatus::kNotANumber:
      throw Error(where + "'" + token + "' is not a number");
    case NumberStatus::kNotFinite:
      break;
  }
  throw Error(where + "non-finite value '" + token + "'");
}

}  // namespace pnpba
