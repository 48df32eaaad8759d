// The benches' percentile of a set of timings: the value at the rounded rank p (n - 1) of the
// sorted values (p = 0.5 the median, 1 the largest), 0 for none. latency_bench,
// registration_bench and moving_object_bench report theirs so, comparable with one another.
#pragma once

#include <algorithm>
#include <vector>

namespace pnpba::bench {

inline double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<size_t>(p * (v.size() - 1) + 0.5))];
}

}  // namespace pnpba::bench
