// The frames' brightness change (pipeline/src/brightness_change.h): a gain and an offset
// recovered from photometric residuals past outliers, the gain's prior on frames of one grey
// level, and the offset-only model's numbers when the gain is off.
#include "brightness_change.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

namespace pnpba {
namespace {

// Photometric residuals of frames whose brightness differs by i2 = gain_factor i1 + offset, with
// Gaussian noise and a share of outliers (occlusions, specularities) far off.
std::vector<DenseResidual> residuals(double gain_factor, double offset, double noise,
                                     double outliers, unsigned seed, bool one_grey = false) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> intensity(20.0, 220.0), unit(0.0, 1.0);
  std::normal_distribution<double> gauss(0.0, noise);
  std::vector<DenseResidual> out;
  for (int i = 0; i < 4000; ++i) {
    DenseResidual r;
    r.i1 = one_grey ? 120.0 : intensity(rng);
    double i2 = gain_factor * r.i1 + offset + gauss(rng);
    if (unit(rng) < outliers) i2 = intensity(rng);
    r.value = i2 - r.i1;
    r.J.setZero();
    out.push_back(r);
  }
  return out;
}

TEST(BrightnessChange, AGainAndAnOffsetAreRecoveredPastOutliers) {
  std::vector<double> scratch;
  for (auto [gain_factor, offset] : {std::pair{1.3, -4.0}, {0.8, 6.0}, {1.0, 0.0}}) {
    const std::vector<DenseResidual> r = residuals(gain_factor, offset, 2.0, 0.1, 7);
    const BrightnessChange c = fitBrightnessChange({&r}, 0.25, 1.345, 1.0, &scratch);
    EXPECT_NEAR(c.gain, gain_factor - 1.0, 0.01) << "gain " << gain_factor;
    EXPECT_NEAR(c.offset, offset, 1.5) << "gain " << gain_factor;
    // What is left is the noise (and the outliers): the robust scale about the true change, not
    // the gain's spread over the intensities.
    std::vector<double> deviations;
    for (const DenseResidual& s : r) {
      deviations.push_back(std::abs(s.value - (gain_factor - 1.0) * s.i1 - offset));
    }
    EXPECT_NEAR(c.sigma, robustSigmaOf(&deviations, 1.0), 0.15) << "gain " << gain_factor;
  }
}

// The residuals split over several spans (the alignment's row bands) give the one fit.
TEST(BrightnessChange, SpansAreOneSet) {
  const std::vector<DenseResidual> all = residuals(1.2, 3.0, 2.0, 0.1, 3);
  const std::vector<DenseResidual> head(all.begin(), all.begin() + 1500);
  const std::vector<DenseResidual> tail(all.begin() + 1500, all.end());
  std::vector<double> scratch;
  const BrightnessChange one = fitBrightnessChange({&all}, 0.25, 1.345, 1.0, &scratch);
  const BrightnessChange two = fitBrightnessChange({&head, &tail}, 0.25, 1.345, 1.0, &scratch);
  EXPECT_EQ(one.gain, two.gain);
  EXPECT_EQ(one.offset, two.offset);
  EXPECT_EQ(one.sigma, two.sigma);
}

// Frames of one grey level cannot tell a gain from an offset: the prior keeps the gain at 0 and
// the offset takes the whole change.
TEST(BrightnessChange, OneGreyLevelKeepsTheGainAtZero) {
  const std::vector<DenseResidual> r = residuals(1.25, 0.0, 1.5, 0.0, 11, /*one_grey=*/true);
  std::vector<double> scratch;
  const BrightnessChange c = fitBrightnessChange({&r}, 0.25, 1.345, 1.0, &scratch);
  EXPECT_LT(std::abs(c.gain), 1e-3);
  EXPECT_NEAR(c.offset + c.gain * 120.0, 0.25 * 120.0, 0.2);
}

// gain_sigma 0: the median offset and the robust scale about it, as the offset-only model gave.
TEST(BrightnessChange, NoGainIsTheMedianOffset) {
  const std::vector<DenseResidual> r = residuals(1.3, 2.0, 2.0, 0.1, 5);
  std::vector<double> values, deviations;
  for (const DenseResidual& s : r) values.push_back(s.value);
  std::vector<double> sorted = values;
  const double median = medianInPlace(&sorted);
  for (double v : values) deviations.push_back(std::abs(v - median));
  std::vector<double> scratch;
  const BrightnessChange c = fitBrightnessChange({&r}, 0.0, 1.345, 1.0, &scratch);
  EXPECT_EQ(c.gain, 0.0);
  EXPECT_EQ(c.offset, median);
  EXPECT_EQ(c.sigma, robustSigmaOf(&deviations, 1.0));
}

}  // namespace
}  // namespace pnpba
