// nearestPixel against std::lround, the rounding it stands in for: halves away from zero, both
// signs, the last representable fractions either side of a half, and what no image holds.
#include "nearest_pixel.h"

#include <gtest/gtest.h>

#include <climits>
#include <cmath>
#include <limits>
#include <random>

namespace pnpba {
namespace {

TEST(NearestPixel, RoundsAsLroundDoes) {
  for (int i = -1000; i <= 1000; ++i) {
    for (double offset : {0.0, 0.25, 0.5, 0.75}) {
      const double x = i + offset;
      for (double y : {x, std::nextafter(x, -1e9), std::nextafter(x, 1e9)}) {
        EXPECT_EQ(nearestPixel(y), std::lround(y)) << y;
      }
    }
  }
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> position(-5000.0, 5000.0);
  for (int k = 0; k < 200000; ++k) {
    const double x = position(random);
    ASSERT_EQ(nearestPixel(x), std::lround(x)) << x;
  }
}

TEST(NearestPixel, FarOrUndefinedPositionsLandOnNoPixel) {
  EXPECT_EQ(nearestPixel(std::numeric_limits<double>::quiet_NaN()), INT_MIN);
  EXPECT_EQ(nearestPixel(std::numeric_limits<double>::infinity()), INT_MIN);
  EXPECT_EQ(nearestPixel(-std::numeric_limits<double>::infinity()), INT_MIN);
  EXPECT_EQ(nearestPixel(1073741824.0), INT_MIN);
  EXPECT_EQ(nearestPixel(-1073741824.0), INT_MIN);
  EXPECT_EQ(nearestPixel(1073741823.4), 1073741823);
}

}  // namespace
}  // namespace pnpba
