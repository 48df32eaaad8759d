// The evaluation plot: rotation and translation error of every pair, one colour per method,
// drawn with OpenCV (no plotting stack to install; the figure is simple enough).
#pragma once

#include <string>
#include <vector>

#include "pnpba/evaluation/evaluation.h"

namespace pnpba {

struct PlotPair {
  int i = 0, j = 0;
  std::vector<PairOutcome> errors;  // one per method, in the methods' order
};

void writeEvaluationPlot(const std::string& path, const std::vector<std::string>& methods,
                         const std::vector<PlotPair>& pairs);

}  // namespace pnpba
