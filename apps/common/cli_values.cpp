#include "cli_values.h"

#include <cmath>
#include <cstdlib>
#include <sstream>

#include "pnpba/core/error.h"
#include "pnpba/core/parse_number.h"

namespace pnpba {

std::vector<double> parseNumberList(const std::string& text, size_t n, const std::string& option) {
  std::vector<double> values;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    double v = 0;
    if (parseNumber(item, &v) != NumberStatus::kOk) {
      throw Error(option + ": '" + item + "' is not a finite number");
    }
    values.push_back(v);
  }
  if (values.size() != n) {
    throw Error(option + ": expected " + std::to_string(n) + " comma-separated numbers, got " +
                std::to_string(values.size()));
  }
  return values;
}

}  // namespace pnpba
