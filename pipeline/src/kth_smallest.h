// The k-th smallest of many doubles, as std::nth_element finds it, with fewer unpredictable
// branches.
//
// The alignment takes three medians at every Gauss-Newton step (the brightness offset, and the
// photometric and geometric robust scales), of a few hundred to 20 000 residuals. nth_element's
// quickselect decides each comparison by a branch that goes either way at random on such data:
// 8.3 ns an element on residuals saved from the real cabinet frames, about 3 ms of CPU a pair
// there. A radix selection counts the values' leading bits into a histogram, keeps the bucket
// that holds rank k and goes on in it with the next bits: 3.9 ns an element on the same
// residuals (docs/benchmarks.md).
#pragma once

#include <cstddef>
#include <vector>

namespace pnpba {

// The value that would stand at position k (0-based, k < values->size()) were *values sorted:
// the same value as std::nth_element(begin, begin + k, end) leaves there (zeros of either sign
// are one value, returned as +0). *values may be reordered. With a NaN among them the order is
// nth_element's own.
double kthSmallest(std::vector<double>* values, size_t k);

}  // namespace pnpba
