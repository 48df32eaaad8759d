// The SIFT retry: a rich-texture pair turned 60 degrees, where ORB's matches run out, is
// recovered by the retry (and reported as SIFT's); without the retry it is refused, not guessed.
#include <gtest/gtest.h>

#include <random>

#include "pnpba/pipeline/two_view.h"
#include "pnpba/synthetic/synthetic_pair.h"

namespace pnpba {
namespace {

// The wide-baseline sweep's rich-texture cell at 60 degrees, 0 m, its first seed.
SyntheticPair sixtyDegreePair() {
  const unsigned seed = 1000 + 60 * 7;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> tilt(-0.3, 0.3);
  const Eigen::Vector3d axis(tilt(rng), rng() % 2 ? 1.0 : -1.0, tilt(rng));
  SyntheticPairOptions o;
  o.seed = seed;
  o.layout = SceneLayout::kClosedRoom;
  o.texture = SceneTexture::kRich;
  o.noise.max_range = 8.0;
  o.T_21 = SyntheticScene::lookAtMotion(60.0, axis, 0.0);
  return renderSyntheticPair(o);
}

TEST(SiftRetry, RecoversALargeRotationOrbCannotMatch) {
  const SyntheticPair p = sixtyDegreePair();
  const Camera camera;  // the renderer's default camera: the textbook intrinsics, x5000 depth
  TwoViewOptions orb_only;
  orb_only.depth_path = DepthPath::kOff;  // judge the feature front end alone
  orb_only.retry_with_sift = false;
  const TwoViewResult orb = estimateTwoView(p.view1.colour, p.view1.depth, p.view2.colour,
                                            p.view2.depth, camera, orb_only);
  EXPECT_FALSE(orb.ok) << "ORB found the 60-degree pose; the retry is not exercised";

  TwoViewOptions with_retry = orb_only;
  with_retry.retry_with_sift = true;
  const TwoViewResult sift = estimateTwoView(p.view1.colour, p.view1.depth, p.view2.colour,
                                             p.view2.depth, camera, with_retry);
  ASSERT_TRUE(sift.ok) << sift.failure;
  EXPECT_EQ(sift.detector, "sift");
  EXPECT_EQ(sift.path, "features");
  const SE3Quat d = sift.T_21 * p.T_21.inverse();
  EXPECT_LT(Eigen::AngleAxisd(d.rotation()).angle() * 180 / M_PI, 2.0);
  EXPECT_LT((sift.T_21.translation() - p.T_21.translation()).norm(), 0.05);
}

TEST(SiftRetry, TheTextbookPresetNeverRetries) {
  EXPECT_FALSE(TwoViewOptions::textbookPreset().retry_with_sift);
  EXPECT_TRUE(TwoViewOptions{}.retry_with_sift);
}

}  // namespace
}  // namespace pnpba
