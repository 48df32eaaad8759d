// The failure rule refuses on evidence of a wrong or undetermined pose, names the rule, and
// leaves imprecise poses alone unless the user sets a precision limit.
#include <gtest/gtest.h>

#include "pnpba/pipeline/two_view.h"

namespace pnpba {
namespace {

// A healthy wide-baseline estimate: many inliers, 1-sigma about 0.6 deg and 8 cm (as measured
// on real pairs 0.2-2 m apart whose true error was of that size).
PoseEvidence wideBaseline() {
  PoseEvidence e;
  e.pairs = 300;
  e.inliers = 200;
  e.chi2_final = 2.2 * 200;
  e.competitor_inliers = 10;
  e.inlier_coverage = 0.7;
  e.covariance_ok = true;
  const double rot = 0.6 / std::sqrt(3.0) * M_PI / 180.0, trans = 0.08 / std::sqrt(3.0);
  e.covariance.diagonal() << rot * rot, rot * rot, rot * rot, trans * trans, trans * trans,
      trans * trans;
  return e;
}

TEST(FailureRule, ImpreciseButDeterminedPosesAreReturned) {
  EXPECT_FALSE(FailureRule{}.check(wideBaseline()).refused());
}

TEST(FailureRule, PrecisionLimitsAreTheUsersAndOffByDefault) {
  FailureRule rule;
  rule.max_sigma_cm = 5.0;
  const FailureVerdict v = rule.check(wideBaseline());
  EXPECT_EQ(v.rule, "max_sigma");
  EXPECT_NE(v.message.find("8.00 cm"), std::string::npos) << v.message;
  rule.max_sigma_cm = 10.0;
  rule.max_sigma_deg = 0.5;
  EXPECT_EQ(rule.check(wideBaseline()).rule, "max_sigma");
}

TEST(FailureRule, EachRuleNamesItself) {
  const FailureRule rule;
  PoseEvidence e = wideBaseline();
  e.inliers = 12;
  e.chi2_final = 20;
  EXPECT_EQ(rule.check(e).rule, "inliers");
  e = wideBaseline();
  e.pairs = 1000;
  EXPECT_EQ(rule.check(e).rule, "inlier_ratio");
  e = wideBaseline();
  e.chi2_final = 10.0 * e.inliers;
  EXPECT_EQ(rule.check(e).rule, "chi2");
  e = wideBaseline();
  e.competitor_inliers = 150;
  EXPECT_EQ(rule.check(e).rule, "ambiguous");
  e = wideBaseline();
  e.pairs = 420;
  e.inlier_coverage = 0.2;
  EXPECT_EQ(rule.check(e).rule, "local_fit");
  e.pairs = 300;  // most pairs agree: a small overlap, not a local fit
  EXPECT_FALSE(rule.check(e).refused());
  e = wideBaseline();
  e.covariance(5, 5) = 0.4 * 0.4;  // one direction unconstrained to 40 cm
  EXPECT_EQ(rule.check(e).rule, "degenerate");
}

TEST(FailureRule, DisabledRefusesNothingAndBadLimitsAreNamed) {
  FailureRule rule;
  rule.enabled = false;
  PoseEvidence e = wideBaseline();
  e.inliers = 3;
  EXPECT_FALSE(rule.check(e).refused());
  FailureRule bad;
  bad.max_sigma_deg = -1;
  EXPECT_NE(bad.validate(), "");
  EXPECT_EQ(FailureRule{}.validate(), "");
}

}  // namespace
}  // namespace pnpba
