// The FPFH's angle bin without atan2 (pipeline/src/registration/angle_bin.h) must be atan2's bin in
// every case, or the descriptors, and the registration, would change.
#include "angle_bin.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace pnpba {
namespace {

TEST(AngleBin, EqualsAtan2sBinOnRandomDirectionsOfEveryScale) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), exponent(-30.0, 30.0);
  int mismatches = 0;
  for (int i = 0; i < 2000000; ++i) {
    const double scale = std::pow(10.0, exponent(rng));
    const double y = unit(rng) * scale, x = unit(rng) * scale;
    mismatches += fastAngleBin(y, x) != exactAngleBin(y, x);
  }
  EXPECT_EQ(mismatches, 0);
}

TEST(AngleBin, EqualsAtan2sBinAtAndAroundEveryBinEdge) {
  // Directions at the edges' angles and a hair either side, where the fit alone would err.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> radius(0.01, 100.0);
  int checked = 0;
  for (int k = 0; k <= 11; ++k) {
    const double edge = -M_PI + 2.0 * M_PI * k / 11.0;
    for (double offset : {0.0, 1e-15, -1e-15, 1e-12, -1e-12, 1e-9, -1e-9, 4e-8, -4e-8, 1e-7, -1e-7,
                          6e-7, -6e-7, 1e-6, -1e-6, 1e-5, -1e-5}) {
      for (int j = 0; j < 50; ++j) {
        const double r = radius(rng), angle = edge + offset;
        const double y = r * std::sin(angle), x = r * std::cos(angle);
        EXPECT_EQ(fastAngleBin(y, x), exactAngleBin(y, x))
            << "edge " << k << " offset " << offset << " y " << y << " x " << x;
        ++checked;
      }
    }
  }
  EXPECT_EQ(checked, 12 * 17 * 50);
}

TEST(AngleBin, ReadsTheSignsOfZerosAsAtan2Does) {
  for (double y : {0.0, -0.0, 1.0, -1.0, 1e-300, -1e-300}) {
    for (double x : {0.0, -0.0, 1.0, -1.0, 1e-300, -1e-300}) {
      EXPECT_EQ(fastAngleBin(y, x), exactAngleBin(y, x)) << "y " << y << " x " << x;
    }
  }
  // The two ends of the range: +pi and -pi (atan2(+0, -1), atan2(-0, -1)) are bins 10 and 0.
  EXPECT_EQ(fastAngleBin(0.0, -1.0), 10);
  EXPECT_EQ(fastAngleBin(-0.0, -1.0), 0);
}

}  // namespace
}  // namespace pnpba
