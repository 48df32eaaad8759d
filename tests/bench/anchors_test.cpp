// latency_bench's anchors, the methods it times beside pnpba: each must return the pose in
// pnpba's convention (T_21, camera 2 from camera 1) on an easy pair, or the bench would count a
// right answer as wrong. Checked against the renderer's exact motion.
#include <gtest/gtest.h>

#include "open3d_odometry_anchor.h"
#include "pnpba/core/plugin.h"
#include "pnpba/evaluation/evaluation.h"
#include "pnpba/evaluation/opencv_baseline.h"
#include "wide_baseline_pairs.h"

namespace pnpba {
namespace {

// The sweep's richly textured room, camera 2 turned 3 degrees and moved 5 cm: a pair any of the
// anchors settles.
SyntheticPair easyPair() {
  SyntheticPairOptions o = bench::wideBaselinePair(bench::SweepScene::kRich, 3.0, 0.05, 0);
  return renderSyntheticPair(o);
}

TEST(LatencyAnchors, OpenCvBaselineReturnsCameraTwoFromCameraOne) {
  const SyntheticPair p = easyPair();
  const Camera camera = bench::estimationCamera(SyntheticCamera{});
  const TwoViewResult r =
      estimateTwoViewOpenCv(p.view1.colour, p.view1.depth, p.view2.colour, camera, {});
  ASSERT_TRUE(r.ok) << r.failure;
  const PoseError e = relativePoseError(r.T_21, p.T_21);
  EXPECT_LT(e.rot_deg, 0.5);
  EXPECT_LT(e.trans_cm, 2.0);
  EXPECT_GT(r.times_ms.total_ms, 0.0);
}

TEST(LatencyAnchors, Open3dOdometryReturnsCameraTwoFromCameraOne) {
  const SyntheticPair p = easyPair();
  const Camera camera = bench::estimationCamera(SyntheticCamera{});
  auto* odometry = pluginFunction<bench::Open3dOdometry>(bench::kOdometryAnchorPlugin,
                                                         bench::kOdometryAnchorSymbol);
  bench::OdometryAnchor a;
  odometry(&p.view1.colour, &p.view1.depth, &p.view2.colour, &p.view2.depth, &camera, 0.0, 10.0,
           &a);
  ASSERT_TRUE(a.ok);
  const PoseError e = relativePoseError(a.T_21, p.T_21);
  EXPECT_LT(e.rot_deg, 0.5);
  EXPECT_LT(e.trans_cm, 2.0);
  // The inverse, camera 1 from camera 2, is twice the motion away: the test tells them apart.
  EXPECT_GT(relativePoseError(a.T_21.inverse(), p.T_21).rot_deg, 5.0);
  EXPECT_GT(a.ms, 0.0);
}

}  // namespace
}  // namespace pnpba
