// evaluate_tum's covariance options: the sensor sigmas reach every pnpba method's covariance and
// nothing else (same poses, same errors), and bad sigmas are an input error naming the problem.
#include <gtest/gtest.h>

#include <string>

#include "pnpba/core/error.h"
#include "pnpba/evaluation/tum_evaluation.h"
#include "shared_data.h"

namespace pnpba {
namespace {

TEST(TumEvaluationCovariance, SensorSigmasReachTheCovarianceAndLeaveThePosesAlone) {
  PNPBA_REQUIRE_SHARED_DATA();
  TumEvaluationOptions o;
  o.folder = test::sharedData("tum_fr1_desk");
  o.gaps = {1};
  o.methods = {"rgbd"};
  const TumEvaluation modelled = evaluateTumSequence(o);
  o.covariance.focal_sigma = o.covariance.principal_point_sigma_px = 0;
  o.covariance.depth_scale_sigma = o.covariance.motion_sigma = 0;
  const TumEvaluation bare = evaluateTumSequence(o);
  ASSERT_EQ(modelled.records.size(), 8u);  // 9 frames, consecutive pairs
  ASSERT_EQ(bare.records.size(), modelled.records.size());
  for (size_t k = 0; k < bare.records.size(); ++k) {
    const PairRecord& m = modelled.records[k];
    const PairRecord& b = bare.records[k];
    ASSERT_TRUE(m.ok && b.ok && m.has_covariance && b.has_covariance) << k;
    EXPECT_EQ(b.error.rot_deg, m.error.rot_deg) << k;
    EXPECT_EQ(b.error.trans_cm, m.error.trans_cm) << k;
    // Without the calibration and motion terms the covariance shrinks, so the same error is
    // more standard deviations away.
    EXPECT_LT(b.sigma_deg, m.sigma_deg) << k;
    EXPECT_LT(b.sigma_cm, m.sigma_cm) << k;
    EXPECT_GT(b.nees, m.nees) << k;
  }
}

TEST(TumEvaluationCovariance, NegativeSigmaIsAnInputError) {
  TumEvaluationOptions o;
  o.folder = "unused";
  o.covariance.focal_sigma = -0.01;
  EXPECT_NE(o.validate().find("calibration sigmas"), std::string::npos) << o.validate();
  EXPECT_THROW(evaluateTumSequence(o), Error);
}

}  // namespace
}  // namespace pnpba
