// TwoViewOptions::time_budget_ms: a stage that does not fit refuses the pair, and a pair gets
// either the answer it gets without a budget or that refusal (time_budget.h).
#include "time_budget.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>

#include "pnpba/core/plugin.h"
#include "pnpba/pipeline/two_view.h"
#include "pnpba/synthetic/synthetic_pair.h"

namespace pnpba {
namespace {

constexpr BudgetedStage kStages[] = {
    BudgetedStage::kFeatureCheck, BudgetedStage::kSeedAlignment,      BudgetedStage::kSiftRetry,
    BudgetedStage::kRegistration, BudgetedStage::kCandidateAlignment, BudgetedStage::kEvidence,
    BudgetedStage::kPluginOpening};

TEST(TimeBudget, WithoutABudgetEveryStageRunsAndNothingIsLearned) {
  TimeBudget none(TimeBudget::Clock::now(), 0.0);
  for (BudgetedStage s : kStages) {
    const double before = TimeBudget::expectedMs(s);
    EXPECT_TRUE(none.allows(s)) << toString(s);
    none.record(s, 1000.0);
    EXPECT_EQ(TimeBudget::expectedMs(s), before) << toString(s);
  }
  EXPECT_FALSE(none.cut());
}

TEST(TimeBudget, TheFirstStageThatDoesNotFitIsNamed) {
  TimeBudget tight(TimeBudget::Clock::now(), 1e-3);
  EXPECT_FALSE(tight.allows(BudgetedStage::kSiftRetry));
  EXPECT_FALSE(tight.allows(BudgetedStage::kRegistration));
  ASSERT_TRUE(tight.cut());
  EXPECT_NE(tight.cutMessage().find("time budget of 0.001 ms"), std::string::npos)
      << tight.cutMessage();
  EXPECT_NE(tight.cutMessage().find("SIFT retry"), std::string::npos) << tight.cutMessage();
  EXPECT_EQ(tight.cutMessage().find("registration"), std::string::npos) << tight.cutMessage();

  // A budget with room for the stage's expected time lets it start.
  const double expected = TimeBudget::expectedMs(BudgetedStage::kRegistration);
  TimeBudget roomy(TimeBudget::Clock::now(), expected + 1000.0);
  EXPECT_TRUE(roomy.allows(BudgetedStage::kRegistration));
  EXPECT_FALSE(roomy.cut());
}

// A stage that started where it fitted asks between its steps whether the deadline passed; if
// it did, the budget is cut there and names the stage.
TEST(TimeBudget, ALongStageIsCutOffAtTheDeadline) {
  using Clock = TimeBudget::Clock;
  TimeBudget none(Clock::now(), 0.0);
  EXPECT_EQ(none.deadline(), Clock::time_point::max());
  EXPECT_FALSE(none.ranOutDuring(BudgetedStage::kCandidateAlignment));
  EXPECT_FALSE(none.cut());

  const Clock::time_point start = Clock::now() - std::chrono::milliseconds(50);
  TimeBudget spent(start, 10.0);
  EXPECT_EQ(spent.deadline(), start + std::chrono::milliseconds(10));
  EXPECT_TRUE(spent.ranOutDuring(BudgetedStage::kCandidateAlignment));
  ASSERT_TRUE(spent.cut());
  EXPECT_NE(spent.cutMessage().find("the time budget of 10 ms"), std::string::npos);
  EXPECT_NE(spent.cutMessage().find("alignment of a registration candidate was cut off"),
            std::string::npos)
      << spent.cutMessage();

  TimeBudget ahead(Clock::now(), 1e6);
  EXPECT_FALSE(ahead.ranOutDuring(BudgetedStage::kSeedAlignment));
  EXPECT_FALSE(ahead.cut());

  // The first cut is the one reported.
  TimeBudget twice(start, 10.0);
  EXPECT_FALSE(twice.allows(BudgetedStage::kSiftRetry));
  const std::string first = twice.cutMessage();
  EXPECT_TRUE(twice.ranOutDuring(BudgetedStage::kEvidence));
  EXPECT_EQ(twice.cutMessage(), first);

  // A budget of years is none: its deadline is the clock's end, not past it.
  EXPECT_EQ(TimeBudget(Clock::now(), 1e15).deadline(), Clock::time_point::max());
}

TEST(TimeBudget, TheExpectationFollowsWhatTheStageTakes) {
  const BudgetedStage s = BudgetedStage::kCandidateAlignment;
  const double typical = TimeBudget::expectedMs(s);
  TimeBudget budget(TimeBudget::Clock::now(), 1e6);
  for (int k = 0; k < 30; ++k) budget.record(s, 4.0);
  EXPECT_NEAR(TimeBudget::expectedMs(s), 4.0, 1e-6);
  // A stage that took almost nothing is still expected to cost something: a spent budget cuts it.
  for (int k = 0; k < 30; ++k) budget.record(s, 0.0);
  EXPECT_GE(TimeBudget::expectedMs(s), 0.1);
  for (int k = 0; k < 60; ++k) budget.record(s, typical);  // as the other tests found it
  EXPECT_NEAR(TimeBudget::expectedMs(s), typical, 1e-6);
}

TEST(TimeBudget, AStageIsExpectedToTakeItsRatePerUnitOfWork) {
  // The registration's expectation is per thousand points it is predicted to keep
  // (registration_work.h): a pair twice the size is expected to take twice as long, and what the
  // stage took is learned per unit of its work.
  const BudgetedStage s = BudgetedStage::kRegistration;
  const double typical = TimeBudget::expectedMs(s);
  TimeBudget learn(TimeBudget::Clock::now(), 1e6);
  for (int k = 0; k < 30; ++k) learn.record(s, 12.0, 3.0);
  EXPECT_NEAR(TimeBudget::expectedMs(s), 4.0, 1e-6);
  learn.record(s, 5.0, 0.0);  // no work predicted: nothing learned from it
  EXPECT_NEAR(TimeBudget::expectedMs(s), 4.0, 1e-6);
  TimeBudget budget(TimeBudget::Clock::now(), 1000.0);
  EXPECT_TRUE(budget.allows(s, 200.0));   // 800 ms expected
  EXPECT_FALSE(budget.allows(s, 300.0));  // 1200 ms
  EXPECT_NE(budget.cutMessage().find("about 1200 ms"), std::string::npos) << budget.cutMessage();
  // What must follow the stage for it to be of use counts too.
  TimeBudget ahead(TimeBudget::Clock::now(), 1000.0);
  EXPECT_TRUE(ahead.allows(s, 200.0, 150.0));   // 800 + 150
  EXPECT_FALSE(ahead.allows(s, 200.0, 250.0));  // 800 + 250
  EXPECT_NE(ahead.cutMessage().find("about 800 ms, and 250 for what it needs after it"),
            std::string::npos)
      << ahead.cutMessage();
  for (int k = 0; k < 60; ++k) learn.record(s, typical);  // as the other tests found it
  EXPECT_NEAR(TimeBudget::expectedMs(s), typical, 1e-6);
}

TEST(TimeBudget, OptionsRejectANegativeOrEndlessBudget) {
  TwoViewOptions o;
  EXPECT_EQ(o.validate(), "");
  for (double bad :
       {-1.0, std::numeric_limits<double>::infinity(), std::numeric_limits<double>::quiet_NaN()}) {
    o.time_budget_ms = bad;
    EXPECT_NE(o.validate().find("time budget"), std::string::npos) << bad;
  }
}

// A pair the depths must carry (a bare room, 45 degrees and 0.5 m: the features are refused)
// and one the feature path settles alone (the sample room, 3 degrees and 12 cm).
SyntheticPair depthPair() {
  SyntheticPairOptions o;
  o.seed = 1066;
  o.layout = SceneLayout::kClosedRoom;
  o.texture = SceneTexture::kPoor;
  o.noise.max_range = 8.0;
  o.T_21 = SyntheticScene::lookAtMotion(45.0, Eigen::Vector3d(0.1, 1.0, -0.2), 0.5);
  return renderSyntheticPair(o);
}

TwoViewResult estimate(const SyntheticPair& p, double budget_ms, int open3d_icp_iterations = 0) {
  TwoViewOptions o;
  o.time_budget_ms = budget_ms;
  o.registration.icp_iterations = open3d_icp_iterations;
  return estimateTwoView(p.view1.colour, p.view1.depth, p.view2.colour, p.view2.depth, Camera{}, o);
}

TEST(TwoViewTimeBudget, APairGetsItsOwnAnswerOrTheBudgetsRefusal) {
  // Each case is checked only if the two pairs take these paths.
  const SyntheticPair pairs[] = {depthPair(), renderSyntheticPair(SyntheticPairOptions{})};
  const char* paths[] = {"depth-registration", "features"};
  for (int i = 0; i < 2; ++i) {
    const SyntheticPair& p = pairs[i];
    const TwoViewResult free = estimate(p, 0.0);
    ASSERT_TRUE(free.ok) << free.failure;
    ASSERT_EQ(free.path, paths[i]);
    // Room for every stage: the same answer, pose for pose.
    const TwoViewResult roomy = estimate(p, 1e6);
    ASSERT_TRUE(roomy.ok) << roomy.failure;
    EXPECT_EQ(roomy.path, free.path);
    EXPECT_TRUE(roomy.T_21.to_homogeneous_matrix() == free.T_21.to_homogeneous_matrix());

    // Room for none: the feature path's own answer stands where it needed no other stage; any
    // other pair is refused, never answered with less evidence.
    const TwoViewResult tight = estimate(p, 1e-3);
    if (free.path == "features") {
      ASSERT_TRUE(tight.ok) << tight.failure;
      EXPECT_TRUE(tight.T_21.to_homogeneous_matrix() == free.T_21.to_homogeneous_matrix());
    } else {
      EXPECT_FALSE(tight.ok);
      EXPECT_EQ(tight.failure_rule, "time_budget");
      EXPECT_NE(tight.failure.find("did not fit"), std::string::npos) << tight.failure;
      EXPECT_EQ(tight.path, "");
      EXPECT_EQ(tight.times_ms.registration_ms, 0.0);  // the registration never started
    }
  }
}

// A process's first registration that takes one of Open3D's steps (here its ICP) opens the
// Open3D plugin first. Under a budget that opening is weighed before it starts: a pair it would
// not fit is refused at once, nothing opened, rather than run past the budget; once open, it is
// never weighed again. The default registration opens nothing and is never weighed for it.
TEST(TwoViewTimeBudget, TheFirstRegistrationsPluginOpeningIsWeighed) {
  if (pluginLoaded("open3d")) GTEST_SKIP() << "the plugin was opened before this test";
  const SyntheticPair p = depthPair();
  constexpr int kIcp = 10;
  // An opening expected to take 1000 s, against a budget of 100 s every other stage fits in.
  TimeBudget teacher(TimeBudget::Clock::now(), 1e9);
  const double typical = TimeBudget::expectedMs(BudgetedStage::kPluginOpening);
  for (int k = 0; k < 60; ++k) teacher.record(BudgetedStage::kPluginOpening, 1e6);
  const TwoViewResult own = estimate(p, 1e5);
  ASSERT_TRUE(own.ok) << own.failure;
  EXPECT_EQ(own.path, "depth-registration");
  EXPECT_GT(own.times_ms.registration_ms, 0.0);
  EXPECT_FALSE(pluginLoaded("open3d"));
  const TwoViewResult cut = estimate(p, 1e5, kIcp);
  EXPECT_FALSE(cut.ok);
  EXPECT_EQ(cut.failure_rule, "time_budget");
  EXPECT_NE(cut.failure.find("opening of the registration's plugin"), std::string::npos)
      << cut.failure;
  EXPECT_NE(cut.failure.find("preloadDepthRegistration()"), std::string::npos) << cut.failure;
  // Said once: the depth path's refusal was that cut.
  EXPECT_EQ(cut.failure.find("preloadDepthRegistration()"),
            cut.failure.rfind("preloadDepthRegistration()"))
      << cut.failure;
  EXPECT_EQ(cut.times_ms.registration_ms, 0.0);
  EXPECT_EQ(cut.times_ms.plugin_load_ms, 0.0);
  EXPECT_FALSE(pluginLoaded("open3d"));
  // Without a budget the pair opens it ...
  const TwoViewResult free = estimate(p, 0.0, kIcp);
  ASSERT_TRUE(free.ok) << free.failure;
  EXPECT_TRUE(pluginLoaded("open3d"));
  EXPECT_GT(free.times_ms.plugin_load_ms, 0.0);
  // ... and, open, the same budget gives the pair its own answer.
  const TwoViewResult open = estimate(p, 1e5, kIcp);
  ASSERT_TRUE(open.ok) << open.failure;
  EXPECT_EQ(open.times_ms.plugin_load_ms, 0.0);
  EXPECT_TRUE(open.T_21.to_homogeneous_matrix() == free.T_21.to_homogeneous_matrix());
  for (int k = 0; k < 60; ++k) teacher.record(BudgetedStage::kPluginOpening, typical);
}

}  // namespace
}  // namespace pnpba
