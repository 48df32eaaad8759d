// A `both` pose (the feature BA and the depth path's alignment agree) is their fusion
// (pose_fusion.h): on a rendered texture-poor pair where both paths run in full.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>

#include "pnpba/pipeline/two_view.h"
#include "pnpba/pipeline/two_view_report.h"
#include "pnpba/synthetic/synthetic_pair.h"
#include "wide_baseline_pairs.h"

namespace pnpba {
namespace {

double nees(const TwoViewResult& r, const SE3Quat& truth) {
  const Vector6d d = (r.T_21 * truth.inverse()).log();
  return d.dot(r.covariance.ldlt().solve(d));
}

TEST(BothPathFusion, TheFusedPoseIsSurerThanTheKeptOneAndStaysHonest) {
  // The poor room turned 20 degrees and moved 1 m: ORB's pose is doubtful, the depth path runs
  // in full and agrees with it.
  const SyntheticPair p =
      renderSyntheticPair(bench::wideBaselinePair(bench::SweepScene::kPoor, 20.0, 1.0, 0));
  TwoViewOptions kept_only;
  kept_only.covariance.fuse_agreeing_poses = false;
  const TwoViewResult kept = estimateTwoView(p.view1.colour, p.view1.depth, p.view2.colour,
                                             p.view2.depth, Camera{}, kept_only);
  const TwoViewResult fused = estimateTwoView(p.view1.colour, p.view1.depth, p.view2.colour,
                                              p.view2.depth, Camera{}, TwoViewOptions{});
  ASSERT_TRUE(kept.ok && fused.ok) << kept.failure << " / " << fused.failure;
  ASSERT_EQ(kept.path, "both");
  EXPECT_EQ(fused.path, "both");
  EXPECT_FALSE(kept.fused);
  EXPECT_TRUE(fused.fused);
  EXPECT_NE(twoViewReportJson(fused, "rgbd").find("\"fused\": true"), std::string::npos);
  // The same decision; a pose moved towards the other estimate, within their agreement.
  EXPECT_EQ(fused.solver, kept.solver);
  const double moved = (fused.T_21 * kept.T_21.inverse()).log().norm();
  EXPECT_GT(moved, 1e-6);
  EXPECT_LT(moved, 0.05);
  // Surer in every direction: kept - fused is positive semi-definite, and strictly smaller. Up
  // to the calibration term: the fused pose's shift under a calibration error is the dense
  // estimate's and the kept one's, weighted, and may reach a little further along a direction
  // than the kept one's alone (measured: 1e-5 of the covariance's size).
  const Eigen::SelfAdjointEigenSolver<Matrix6d> gap(kept.covariance - fused.covariance);
  EXPECT_GT(gap.eigenvalues().minCoeff(), -1e-3 * kept.covariance.norm());
  EXPECT_LT(fused.covariance.trace(), 0.9 * kept.covariance.trace());
  EXPECT_LE(fused.judged_covariance.trace(), kept.judged_covariance.trace());
  // The calibration term is carried, not dropped: it is in the fused covariance.
  EXPECT_GT(fused.calibration_sensitivity.norm(), 0.0);
  // Honest against the renderer's exact pose (95 % bound of chi2(6)), and as accurate.
  EXPECT_LT(nees(fused, p.T_21), 12.59);
  EXPECT_GT(fused.depth_consistency, 0.9);
  EXPECT_EQ(fused.slide_sigma_m, Eigen::Vector3d::Zero());
}

TEST(BothPathFusion, TheSlideFloorStaysWithTheDepthPathsOwnPose) {
  // The slide term is a floor on how loosely the depths alone pin a slide. A fused pose has
  // the feature pairs pinning it, so the dense estimate enters the fusion without the floor:
  // the fused pose and covariance are the same with the term on or off. (With the floor on the
  // dense part the fused translation had read the feature BA's alone: the poor room's `both`
  // poses, covariance_bench, mean NEES 3.4 with it and 4.2-4.4 without.)
  const SyntheticPair p =
      renderSyntheticPair(bench::wideBaselinePair(bench::SweepScene::kPoor, 20.0, 1.0, 0));
  TwoViewOptions no_slide;
  no_slide.covariance.slide_probe_m = 0;
  const TwoViewResult with = estimateTwoView(p.view1.colour, p.view1.depth, p.view2.colour,
                                             p.view2.depth, Camera{}, TwoViewOptions{});
  const TwoViewResult without = estimateTwoView(p.view1.colour, p.view1.depth, p.view2.colour,
                                                p.view2.depth, Camera{}, no_slide);
  ASSERT_TRUE(with.ok && without.ok) << with.failure << " / " << without.failure;
  ASSERT_TRUE(with.fused && without.fused);
  EXPECT_LT((with.T_21 * without.T_21.inverse()).log().norm(), 1e-12);
  EXPECT_LT((with.covariance - without.covariance).norm(), 1e-12 * with.covariance.norm());
}

}  // namespace
}  // namespace pnpba
