// Private to the depth-only registration (registration.cpp): the FPFH's sum of its neighbours'
// 33-bin histograms, each weighted by 1 / squared distance (fpfh.cpp), four bins at a time where
// the CPU has AVX2. Each bin is summed as the scalar code sums it, fl(sum + fl(w h)) neighbour
// after neighbour, with no fused multiply-add (the file is built with -mavx2 alone and
// -ffp-contract=off): the same bits.
#pragma once

namespace pnpba {

// out[0..32] = sum over the k neighbours j with distance2[j] != 0 (the point itself is left
// out) of (1 / distance2[j]) * histograms[33 * index[j] ..]; histograms is 33 x n, column-major.
// Call only where cpuHasAvx2Fma().
void weightedHistogramSumAvx2(const double* histograms, const int* index, const double* distance2,
                              int k, double* out);

}  // namespace pnpba
