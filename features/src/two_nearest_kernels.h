// Brute-force two nearest neighbours of descriptor rows, one kernel per instruction set. Each
// returns, per query row, its nearest and second nearest train rows as BFMatcher's knnMatch(k = 2)
// does (the first of equal distances keeps its place), so the choice of kernel never changes a
// match; matching.cpp picks the fastest the CPU runs.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

#include "pnpba/features/matching.h"

namespace pnpba::kernels {

using Neighbours = std::vector<std::vector<cv::DMatch>>;

// Train rows in blocks of eight, 64-bit word by word: a block holds word 0 of its eight rows, then
// word 1, 2 and 3 (256 bytes), so that a vector register holds one word of four or eight rows and
// their distances to a query add up lane by lane. Rows past the last whole block are not in it.
std::vector<uint64_t> wordMajorBlocks(const cv::Mat& train);

// 32-byte descriptors (CV_8U, continuous), query rows [begin, end) into (*out)[q].
void hammingScalar(const cv::Mat& query, const cv::Mat& train, int begin, int end, Neighbours* out);
void hammingAvx2(const cv::Mat& query, const cv::Mat& train, const std::vector<uint64_t>& blocks,
                 int begin, int end, Neighbours* out);
void hammingAvx512(const cv::Mat& query, const cv::Mat& train, const std::vector<uint64_t>& blocks,
                   int begin, int end, Neighbours* out);

// 128-element descriptors whose values are whole numbers 0-255 (SIFT's): every partial sum of
// squared differences is then a whole number below 2^24, exact in float in any order, so these
// give BFMatcher's distances to the bit. l2Avx2 takes them as 16-bit integers (CV_16S,
// continuous; half the floats' memory, and 16 elements an instruction), l2Avx512 as the
// floats they are.
void l2Avx2(const cv::Mat& query, const cv::Mat& train, int begin, int end, Neighbours* out);
void l2Avx512(const cv::Mat& query, const cv::Mat& train, int begin, int end, Neighbours* out);

}  // namespace pnpba::kernels
