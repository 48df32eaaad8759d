// Nearest descriptors both ways: equal, index for index, to a plain scan that sums each squared
// distance in dimension order (with std::fma, or a product and a sum for the portable kernel)
// and keeps the first of equal distances; for any number of threads and for sizes around the
// vector lanes and query steps.
#include "pnpba/pipeline/nearest_descriptors.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace pnpba {
namespace {

std::vector<int> scanNearest(const std::vector<float>& from, int rows_from,
                             const std::vector<float>& to, int rows_to, int dim,
                             bool fused = true) {
  std::vector<int> nearest(rows_from, -1);
  for (int i = 0; i < rows_from; ++i) {
    float best = std::numeric_limits<float>::infinity();
    for (int j = 0; j < rows_to; ++j) {
      float sum = 0;
      for (int k = 0; k < dim; ++k) {
        const float d = to[j * dim + k] - from[i * dim + k];
        sum = fused ? std::fma(d, d, sum) : sum + d * d;
      }
      if (sum < best) best = sum, nearest[i] = j;
    }
  }
  return nearest;
}

// FPFH-like rows (non-negative, 0-200), a share of them exact copies of others: equal distances.
std::vector<float> descriptors(int rows, int dim, std::mt19937* rng) {
  std::uniform_real_distribution<float> value(0.0f, 200.0f);
  std::vector<float> d(static_cast<size_t>(rows) * dim);
  for (float& v : d) v = value(*rng);
  for (int r = 1; r < rows; ++r) {
    if ((*rng)() % 5 == 0) {
      const int source = static_cast<int>((*rng)() % r);
      std::copy_n(d.begin() + source * dim, dim, d.begin() + r * dim);
    }
  }
  return d;
}

TEST(NearestDescriptors, EqualAPlainScanBothWaysForAnyThreadCount) {
  std::mt19937 rng(3);
  for (int dim : {33, 7}) {
    for (auto [rows_a, rows_b] :
         {std::pair{1, 1}, {3, 5}, {4, 16}, {5, 17}, {9, 31}, {120, 77}, {301, 513}}) {
      const std::vector<float> a = descriptors(rows_a, dim, &rng);
      std::vector<float> b = descriptors(rows_b, dim, &rng);
      // Some rows of B are copies of rows of A: distance 0, the first copy must win.
      for (int r = 0; r < rows_b; r += 3) {
        std::copy_n(a.begin() + (r % rows_a) * dim, dim, b.begin() + r * dim);
      }
      const std::vector<int> a_to_b = scanNearest(a, rows_a, b, rows_b, dim);
      const std::vector<int> b_to_a = scanNearest(b, rows_b, a, rows_a, dim);
      for (int threads : {1, 2, 3}) {
        const NearestBothWays n = nearestBothWays(a.data(), rows_a, b.data(), rows_b, dim, threads);
        EXPECT_EQ(n.a_to_b, a_to_b)
            << rows_a << " x " << rows_b << ", dim " << dim << ", " << threads << " threads";
        EXPECT_EQ(n.b_to_a, b_to_a)
            << rows_a << " x " << rows_b << ", dim " << dim << ", " << threads << " threads";
      }
      // Every kernel this CPU runs gives the same answer: the fused ones (AVX-512, AVX2) the
      // fused scan's, the portable one (runs everywhere) a scan that multiplies and adds apart.
      const std::vector<int> a_to_b_apart = scanNearest(a, rows_a, b, rows_b, dim, false);
      const std::vector<int> b_to_a_apart = scanNearest(b, rows_b, a, rows_a, dim, false);
      for (int lanes : {16, 8, 4}) {
        NearestBothWays n;
        if (!detail::nearestBothWaysOn(lanes, a.data(), rows_a, b.data(), rows_b, dim, 2, &n)) {
          continue;
        }
        EXPECT_EQ(n.a_to_b, lanes == 4 ? a_to_b_apart : a_to_b)
            << rows_a << " x " << rows_b << ", " << lanes << " lanes";
        EXPECT_EQ(n.b_to_a, lanes == 4 ? b_to_a_apart : b_to_a)
            << rows_a << " x " << rows_b << ", " << lanes << " lanes";
      }
    }
  }
}

TEST(NearestDescriptors, EmptySetsGiveNoNeighbours) {
  const std::vector<float> a(33, 1.0f);
  const NearestBothWays n = nearestBothWays(a.data(), 1, nullptr, 0, 33);
  EXPECT_EQ(n.a_to_b, std::vector<int>{-1});
  EXPECT_TRUE(n.b_to_a.empty());
}

}  // namespace
}  // namespace pnpba
