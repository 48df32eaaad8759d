// The depth path's refusal table (pipeline/src/depth_path_judging.h), row by row: a candidate
// every rule lets stand, then one field of it changed per row, and the rule that row names fires.
#include "depth_path_judging.h"

#include <gtest/gtest.h>

#include <functional>
#include <string>
#include <vector>

namespace pnpba {
namespace {

const SE3Quat kPose(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.1, 0, 0));
const SE3Quat kOtherPose(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY()).toRotationMatrix(),
                         Eigen::Vector3d(-0.2, 0, 0));

DepthCandidate standingCandidate() {
  DepthCandidate c;
  c.seed = "registration";
  c.T_seed = c.T = kPose;
  c.consistency = 0.99;
  c.fitness = 0.8;
  c.explained = 40;
  c.rank = 0;
  c.evidence.photometric_agreement = 0.95;
  c.evidence.depth1_samples = 1000;
  c.evidence.geometric_samples = 800;  // overlap 0.8
  return c;
}

TwoViewResult resultFor(const DepthCandidate& c, int pairs) {
  TwoViewResult r;
  r.T_21 = c.T;
  r.pairs.resize(pairs);
  r.depth_consistency = c.consistency;
  r.covariance_ok = true;
  r.judged_covariance = 1e-6 * Eigen::Matrix<double, 6, 6>::Identity();
  return r;
}

struct Row {
  std::string rule;
  std::function<void(std::vector<DepthCandidate>*, TwoViewResult*)> change;
};

TEST(DepthPathJudging, EachRowOfTheTableRefusesAsItSays) {
  const TwoViewOptions options;
  {
    const std::vector<DepthCandidate> alone = {standingCandidate()};
    const FailureVerdict v = judgeDepthPose(alone, 0, resultFor(alone[0], 60), options);
    ASSERT_FALSE(v.refused()) << v.rule << ": " << v.message;
  }
  const std::vector<Row> rows = {
      // The depths alone carry it (too few pairs) and support it below the depth-only bound.
      {"depth_inconsistent",
       [](std::vector<DepthCandidate>* c, TwoViewResult*) {
         (*c)[0].explained = 10;
         (*c)[0].consistency = 0.93;
       }},
      // A second supported candidate at another pose, with the same evidence.
      {"rival_alignment",
       [](std::vector<DepthCandidate>* c, TwoViewResult*) {
         DepthCandidate rival = (*c)[0];
         rival.seed = "registration rival";
         rival.T = kOtherPose;
         rival.rank = 1;
         c->push_back(rival);
       }},
      {"features_disagree",
       [](std::vector<DepthCandidate>* c, TwoViewResult* r) {
         (*c)[0].explained = 2;  // of 60 pairs, < 5 %
         (*c)[0].consistency = 0.99;
         r->pairs.resize(60);
       }},
      {"photometric", [](std::vector<DepthCandidate>* c,
                         TwoViewResult*) { (*c)[0].evidence.photometric_agreement = 0.6; }},
      {"degenerate",
       [](std::vector<DepthCandidate>*, TwoViewResult* r) { r->covariance_ok = false; }},
      {"registration_overlap",
       [](std::vector<DepthCandidate>* c, TwoViewResult*) { (*c)[0].fitness = 0.1; }},
      // The depths alone carry it over a fifth of frame 1 (< a quarter).
      {"registration_overlap",
       [](std::vector<DepthCandidate>* c, TwoViewResult*) {
         (*c)[0].explained = 10;
         (*c)[0].evidence.geometric_samples = 200;
       }},
  };
  for (const Row& row : rows) {
    std::vector<DepthCandidate> candidates = {standingCandidate()};
    TwoViewResult r = resultFor(candidates[0], 60);
    row.change(&candidates, &r);
    r.depth_consistency = candidates[0].consistency;
    EXPECT_EQ(judgeDepthPose(candidates, 0, r, options).rule, row.rule);
  }
}

TEST(DepthPathJudging, TheClearlyBetterCandidateWinsAndLeavesNoRival) {
  const TwoViewOptions options;
  DepthCandidate weaker = standingCandidate();
  weaker.T = kOtherPose;
  weaker.consistency = 0.91;  // supported, but clearly below
  weaker.rank = 1;
  const std::vector<DepthCandidate> candidates = {weaker, standingCandidate()};
  const size_t best = bestCandidate(candidates, options);
  EXPECT_EQ(best, 1u);
  EXPECT_TRUE(clearlyBetter(candidates[1], candidates[0], options));
  EXPECT_FALSE(clearlyBetter(candidates[0], candidates[1], options));
  EXPECT_FALSE(
      judgeDepthPose(candidates, best, resultFor(candidates[best], 60), options).refused());
}

}  // namespace
}  // namespace pnpba
