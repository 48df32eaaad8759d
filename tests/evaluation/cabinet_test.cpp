// The real texture-poor scene: the shared TUM fr3_cabinet key frames, pairs (i, i+1) and
// (i, i+3), and 26-76 degrees apart, scored against the motion-capture ground truth as
// evaluate_tum does. The depth path's refinement, its candidates and its refusals must keep every
// returned pose right, and its covariance must cover the error without inflating it.
#include <gtest/gtest.h>

#include <utility>
#include <vector>

#include "pnpba/evaluation/tum_evaluation.h"
#include "shared_data.h"

namespace pnpba {
namespace {

// The key frames' pairs (i, i + k) for the given k, the default pipeline (rgbd).
TumEvaluationOptions cabinetPairs(std::vector<int> gaps) {
  TumEvaluationOptions o;
  o.folder = test::sharedData("tum_fr3_cabinet_keyframes");
  o.camera_path = std::string(PNPBA_SOURCE_DIR) + "/data/cameras/tum_fr3.yaml";
  o.gaps = std::move(gaps);
  o.methods = {"rgbd"};
  return o;
}

TEST(CabinetKeyFrames, DefaultPipelineIsRightOrRefusesOnARealTexturePoorScene) {
  PNPBA_REQUIRE_SHARED_DATA();
  const TumEvaluationOptions o = cabinetPairs({1, 3});
  const TumEvaluation ev = evaluateTumSequence(o);
  const MethodSummary& s = ev.summaries.at("rgbd");
  ASSERT_EQ(s.pairs, 54);  // 28 + 26 pairs of 29 frames
  // Measured: 52 of 54 within 2 deg / 5 cm, none wrong (docs/two_view.md); the bar is 60 %
  // (33 of 54) and no wrong pose.
  EXPECT_GE(s.within_2deg_5cm, 33);
  EXPECT_EQ(s.wrong, 0);
  // Nothing returned is far off: every returned pose within 5 deg / 20 cm.
  EXPECT_EQ(s.within_5deg_20cm, s.pairs - s.failures);
}

// Key frames 26-76 degrees and 0.5-1.5 m apart, (i, i+5) and (i, i+8): the reported covariance
// must cover the error (inside the 95 % bound) without the 1-sigma of three to four times the
// error the uncapped motion term gave (mean NEES 0.7): the unmodelled error levels off at the
// sensor's floor. The poses are the same either way.
TEST(CabinetKeyFrames, CovarianceCoversWideBaselinesWithoutInflatingThem) {
  PNPBA_REQUIRE_SHARED_DATA();
  TumEvaluationOptions o = cabinetPairs({5, 8});
  const TumEvaluation capped = evaluateTumSequence(o);
  o.covariance.motion_cap_deg = o.covariance.motion_cap_m = 0;
  o.covariance.motion_sigma = 0.05;  // the former linear term
  const TumEvaluation linear = evaluateTumSequence(o);
  const MethodSummary& s = capped.summaries.at("rgbd");
  const MethodSummary& l = linear.summaries.at("rgbd");
  ASSERT_EQ(s.pairs, 45);               // 24 + 21 pairs of 29 frames
  ASSERT_GE(s.pairs - s.failures, 15);  // measured: 30
  EXPECT_EQ(s.failures, l.failures);
  // The registration's rivals, screened (TwoViewOptions::aligned_registration_candidates): 27
  // within 2 deg / 5 cm where the one-pose search found 19; the bar is 24, and no wrong pose.
  EXPECT_GE(s.within_2deg_5cm, 24);
  EXPECT_EQ(s.wrong, 0);
  // Measured: 100 % inside, NEES median 1.6 (capped) against 0.5 (linear).
  EXPECT_GE(s.nees_inside95, 0.9);
  EXPECT_GE(s.rot_within_2sigma, 0.9);
  EXPECT_GE(s.trans_within_2sigma, 0.9);
  EXPECT_GT(s.nees_median, 2 * l.nees_median);
  EXPECT_GT(s.nees_median, 0.9);
}

}  // namespace
}  // namespace pnpba
