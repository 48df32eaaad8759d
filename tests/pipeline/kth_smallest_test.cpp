// kthSmallest against std::nth_element, the selection it replaces: the same value at every rank
// asked, on the shapes of data the alignment's medians see and on the awkward ones.
#include "kth_smallest.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "rgbd_residuals.h"  // medianInPlace

namespace pnpba {
namespace {

double byNthElement(std::vector<double> v, size_t k) {
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[k];
}

// Every rank of a small set, and for a large one the extremes, the median and a spread of others.
void expectSameAsNthElement(const std::vector<double>& values, const char* what) {
  const size_t n = values.size();
  std::vector<size_t> ranks;
  if (n <= 600) {
    for (size_t k = 0; k < n; ++k) ranks.push_back(k);
  } else {
    for (size_t k :
         {size_t{0}, size_t{1}, n / 4, n / 2 - 1, n / 2, n / 2 + 1, 3 * n / 4, n - 2, n - 1}) {
      ranks.push_back(k);
    }
    for (size_t k = 7; k < n; k += n / 37 + 1) ranks.push_back(k);
  }
  for (size_t k : ranks) {
    std::vector<double> v = values;
    const double ours = kthSmallest(&v, k);
    const double expected = byNthElement(values, k);
    ASSERT_EQ(ours, expected) << what << ", " << n << " values, rank " << k;
    ASSERT_FALSE(std::signbit(ours) && ours == 0) << "a zero comes back as +0";
  }
}

TEST(KthSmallest, MatchesNthElementOnResidualLikeData) {
  std::mt19937 random(7);
  std::student_t_distribution<double> heavy_tailed(3.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (size_t n : {1u, 2u, 3u, 255u, 256u, 257u, 600u, 1000u, 4800u, 19200u, 76800u}) {
    std::vector<double> residuals(n), deviations(n), depths(n);
    for (size_t i = 0; i < n; ++i) {
      residuals[i] = 4.0 * heavy_tailed(random) + 0.3;   // photometric: an offset, outliers
      deviations[i] = std::abs(0.02 * normal(random));   // |geometric|: all positive
      depths[i] = 0.5 + 3.0 * std::abs(normal(random));  // metres
    }
    expectSameAsNthElement(residuals, "heavy-tailed residuals");
    expectSameAsNthElement(deviations, "absolute deviations");
    expectSameAsNthElement(depths, "depths");
  }
}

TEST(KthSmallest, MatchesNthElementOnAwkwardData) {
  std::mt19937 random(11);
  std::uniform_int_distribution<int> small(-3, 3);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double inf = std::numeric_limits<double>::infinity();
  for (size_t n : {300u, 5000u, 40000u}) {
    std::vector<double> few_values(n), with_zeros(n), wide(n), extremes(n), near_ties(n);
    for (size_t i = 0; i < n; ++i) {
      few_values[i] = small(random);  // many equal values (whole intensities)
      with_zeros[i] = i % 3 == 0 ? (i % 2 ? -0.0 : 0.0) : small(random) * unit(random);
      wide[i] = std::ldexp(unit(random) - 0.5, small(random) * 300);  // exponents far apart
      const int kind = static_cast<int>(i % 5);
      extremes[i] = kind == 0   ? inf
                    : kind == 1 ? -inf
                    : kind == 2 ? std::numeric_limits<double>::denorm_min() * (i % 7)
                    : kind == 3 ? std::numeric_limits<double>::max()
                                : -std::numeric_limits<double>::lowest() * unit(random);
      // Doubles one unit in the last place apart: only the last bits tell them apart.
      near_ties[i] = std::nextafter(1.0, 2.0 * (i % 2)) + (i % 4) * 1e-16;
    }
    std::vector<double> equal(n, 2.5);
    std::vector<double> ascending(n), descending(n);
    for (size_t i = 0; i < n; ++i) ascending[i] = static_cast<double>(i), descending[i] = -1.0 * i;
    expectSameAsNthElement(few_values, "few distinct values");
    expectSameAsNthElement(with_zeros, "zeros of both signs");
    expectSameAsNthElement(wide, "exponents far apart");
    expectSameAsNthElement(extremes, "infinities, denormals and the largest doubles");
    expectSameAsNthElement(near_ties, "values one ulp apart");
    expectSameAsNthElement(equal, "all equal");
    expectSameAsNthElement(ascending, "ascending");
    expectSameAsNthElement(descending, "descending");
  }
}

TEST(KthSmallest, ANanLeavesTheOrderToNthElement) {
  std::vector<double> v(1000);
  for (size_t i = 0; i < v.size(); ++i) v[i] = std::sin(static_cast<double>(i));
  v[500] = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> ours = v;
  const double expected = byNthElement(v, 10);
  EXPECT_EQ(kthSmallest(&ours, 10), expected);
}

TEST(KthSmallest, MedianInPlaceIsTheUpperMiddle) {
  std::vector<double> v = {5, 1, 4, 2, 3, 6};
  EXPECT_EQ(medianInPlace(&v), 4.0);
  std::vector<double> odd(1001);
  for (size_t i = 0; i < odd.size(); ++i) odd[i] = static_cast<double>((i * 389) % 1001);
  EXPECT_EQ(medianInPlace(&odd), 500.0);
  std::vector<double> none;
  EXPECT_EQ(medianInPlace(&none), 0.0);
}

}  // namespace
}  // namespace pnpba
