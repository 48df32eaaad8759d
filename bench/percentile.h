// The benches' percentile of a set of timings: the value at the rounded rank p (n - 1) of the
// sorted values (p = 0.5 the median, 1 the largest), 0 for none. latency_bench,
// registration_bench and moving_object_bench report theirs so, comparable with one another and
// with evaluate_tum's (one rule, pnpba::rankPercentile).
#pragma once

#include <utility>
#include <vector>

#include "pnpba/evaluation/evaluation.h"

namespace pnpba::bench {

inline double percentile(std::vector<double> v, double p) {
  return rankPercentile(std::move(v), p);
}

}  // namespace pnpba::bench
