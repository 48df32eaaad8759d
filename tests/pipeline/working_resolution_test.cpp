// Images larger than 640 x 480: the depth path and the SIFT retry work on them scaled down to
// its pixel count (two_view_stages.h: workingScale, DepthPathView), so that a high-resolution
// sensor costs what 640 x 480 costs; the poses they find are checked against the renderer's
// truth at 1.3 and twice the sweep's resolution. The depth registration strides a larger image
// further and coarsens its voxel for a wider view, to keep 640 x 480's number of points.
#include <gtest/gtest.h>

#include <cmath>

#include "pnpba/pipeline/depth_registration.h"
#include "pnpba/pipeline/two_view.h"
#include "pnpba/synthetic/synthetic_pair.h"
#include "resized_pair.h"
#include "two_view_stages.h"
#include "wide_baseline_pairs.h"

namespace pnpba {
namespace {

double angleDeg(const SE3Quat& a, const SE3Quat& b) {
  return Eigen::AngleAxisd((a * b.inverse()).rotation()).angle() * 180 / M_PI;
}

// A sweep pair as a sensor of `factor` times its resolution sees it.
struct EnlargedPair {
  SyntheticPair rendered;
  cv::Mat image1, depth1, image2, depth2;
  Camera camera;  // the renderer's intrinsics (Camera's defaults), then enlarged
};

EnlargedPair enlargedPair(bench::SweepScene scene, double deg, double metres, double factor = 2.0) {
  EnlargedPair e;
  e.rendered = renderSyntheticPair(bench::wideBaselinePair(scene, deg, metres, 0));
  e.image1 = e.rendered.view1.colour, e.depth1 = e.rendered.view1.depth;
  e.image2 = e.rendered.view2.colour, e.depth2 = e.rendered.view2.depth;
  bench::resizePair(factor, &e.image1, &e.depth1, &e.image2, &e.depth2, &e.camera);
  return e;
}

// Within 2 degrees and 5 cm of the renderer's truth.
void expectNearTruth(const TwoViewResult& r, const SE3Quat& truth) {
  EXPECT_LT(angleDeg(r.T_21, truth), 2.0);
  EXPECT_LT((r.T_21.translation() - truth.translation()).norm(), 0.05);
}

// The enlarged pair's pose from the SIFT retry, within 2 degrees and 5 cm.
void expectSiftRecovers(const EnlargedPair& e, const TwoViewOptions& options) {
  const TwoViewResult r =
      estimateTwoView(e.image1, e.depth1, e.image2, e.depth2, e.camera, options);
  ASSERT_TRUE(r.ok) << r.failure;
  EXPECT_EQ(r.detector, "sift");
  expectNearTruth(r, e.rendered.T_21);
}

TEST(WorkingResolution, ScalesImagesLargerThan640x480DownToItsPixelCount) {
  EXPECT_EQ(workingScale({640, 480}), 1.0);
  EXPECT_EQ(workingScale({739, 458}), 1.0);  // within 15 %
  EXPECT_DOUBLE_EQ(workingScale({1280, 960}), 0.5);
  EXPECT_DOUBLE_EQ(workingScale({2560, 1920}), 0.25);
  EXPECT_NEAR(workingScale({832, 624}), 640.0 / 832, 1e-12);
  EXPECT_NEAR(workingScale({1280, 720}) * workingScale({1280, 720}) * 1280 * 720, 640 * 480, 1e-6);
}

TEST(WorkingResolution, ViewSharesSmallImagesAndHalvesLargeOnesAsThePyramidDoes) {
  Camera camera;
  camera.width = 640, camera.height = 480;
  cv::Mat colour(480, 640, CV_8UC3, cv::Scalar(10, 20, 30)), depth(480, 640, CV_16U);
  cv::randu(depth, 1000, 20000);
  const DepthPathView same = depthPathView(colour, depth, colour, depth, camera);
  EXPECT_EQ(same.halvings, 0);
  EXPECT_EQ(same.depth1.data, depth.data);  // no copy
  EXPECT_EQ(same.camera.pinhole.fx, camera.pinhole.fx);

  cv::Mat big_colour(960, 1280, CV_8UC3, cv::Scalar(10, 20, 30)), big_depth(960, 1280, CV_16U);
  cv::randu(big_depth, 1000, 20000);
  Camera big = camera;
  big.pinhole.fx = 1000, big.pinhole.fy = 1001, big.pinhole.cx = 640.5, big.pinhole.cy = 480.25;
  big.width = 1280, big.height = 960;
  const DepthPathView half = depthPathView(big_colour, big_depth, big_colour, cv::Mat(), big);
  EXPECT_EQ(half.halvings, 1);
  ASSERT_EQ(half.image1.size(), cv::Size(640, 480));
  ASSERT_EQ(half.depth1.size(), cv::Size(640, 480));
  EXPECT_TRUE(half.depth2.empty());
  for (int v = 0; v < 480; v += 37) {
    for (int u = 0; u < 640; u += 41) {
      EXPECT_EQ(half.depth1.at<uint16_t>(v, u), big_depth.at<uint16_t>(2 * v, 2 * u));
    }
  }
  // Pixel u' of the half image sits on pixel 2 u' of the full one.
  EXPECT_DOUBLE_EQ(half.camera.pinhole.fx, 500);
  EXPECT_DOUBLE_EQ(half.camera.pinhole.fy, 500.5);
  EXPECT_DOUBLE_EQ(half.camera.pinhole.cx, 320.25);
  EXPECT_DOUBLE_EQ(half.camera.pinhole.cy, 240.125);
  EXPECT_EQ(half.camera.width, 640);
  EXPECT_EQ(half.camera.height, 480);
  // Grey in floats: OpenCV's grey of (B, G, R) = (10, 20, 30), 0.114 B + 0.587 G + 0.299 R, in
  // whole numbers as the pyramid of a 640 x 480 pair makes it.
  ASSERT_EQ(half.image1.type(), CV_32FC1);
  EXPECT_NEAR(half.image1.at<float>(100, 100), 22.0f, 1e-4);
}

// Between two halvings (832 x 624) the view is resampled to 640 x 480: grey by area, depth from
// the nearest pixel centre, the intrinsics with pixel centres kept.
TEST(WorkingResolution, ViewResamplesImagesBetweenHalvingsTo640x480) {
  cv::Mat colour(624, 832, CV_8UC3, cv::Scalar(10, 20, 30)), depth(624, 832, CV_16U);
  cv::randu(depth, 1000, 20000);
  Camera camera;
  camera.pinhole.fx = 600, camera.pinhole.fy = 601, camera.pinhole.cx = 415.5;
  camera.pinhole.cy = 311.5;
  camera.width = 832, camera.height = 624;
  const DepthPathView view = depthPathView(colour, depth, colour, depth, camera);
  EXPECT_EQ(view.halvings, 0);
  ASSERT_EQ(view.image1.size(), cv::Size(640, 480));
  ASSERT_EQ(view.depth2.size(), cv::Size(640, 480));
  const double s = 640.0 / 832;
  EXPECT_DOUBLE_EQ(view.camera.pinhole.fx, 600 * s);
  EXPECT_DOUBLE_EQ(view.camera.pinhole.fy, 601 * s);
  EXPECT_DOUBLE_EQ(view.camera.pinhole.cx, 319.5);  // the image centre stays the centre
  EXPECT_DOUBLE_EQ(view.camera.pinhole.cy, 239.5);
  EXPECT_EQ(view.camera.width, 640);
  for (int v = 0; v < 480; v += 37) {
    for (int u = 0; u < 640; u += 41) {
      // The full-resolution pixel whose area holds the working pixel's centre.
      const int fu = static_cast<int>(std::floor((u + 0.5) / s));
      const int fv = static_cast<int>(std::floor((v + 0.5) / s));
      EXPECT_EQ(view.depth1.at<uint16_t>(v, u), depth.at<uint16_t>(fv, fu)) << u << " " << v;
    }
  }
  ASSERT_EQ(view.image1.type(), CV_32FC1);
  EXPECT_NEAR(view.image1.at<float>(100, 100), 22.0f, 1e-4);  // as above
}

// The sweep's texture-poor room at 45 degrees and 0.5 m, which only the depth path solves, as a
// 1280 x 960 sensor sees it (halved) and as an 832 x 624 one does (resampled to 640 x 480).
TEST(WorkingResolution, DepthPathPoseHoldsAtLargerResolutions) {
  // The pose is a rival of the registration's best-supported one over 26 % of frame 1 at 2x,
  // which the default refuses (min_rival_depth_only_overlap); the subject here is the working
  // resolution, so a rival needs what any depth-only pose needs.
  TwoViewOptions options;
  options.min_rival_depth_only_overlap = options.min_depth_only_overlap;
  for (const double factor : {2.0, 1.3}) {
    const EnlargedPair e = enlargedPair(bench::SweepScene::kPoor, 45.0, 0.5, factor);
    ASSERT_EQ(e.image1.cols, std::lround(640 * factor));
    const TwoViewResult r =
        estimateTwoView(e.image1, e.depth1, e.image2, e.depth2, e.camera, options);
    ASSERT_TRUE(r.ok) << factor << "x: " << r.failure;
    EXPECT_EQ(r.path, "depth-registration") << factor << "x";
    expectNearTruth(r, e.rendered.T_21);
  }
}

// Above OrbOptions::max_pixels ORB works on a shrunk copy: at 2.6 times the sweep's resolution
// (1664 x 1248, about 1920 x 1080's pixel count) the rich room at 15 degrees and 0.25 m is still
// settled by the features within 2 degrees and 5 cm, whose keypoints lie on the image's pixels.
TEST(WorkingResolution, FeaturePathHoldsAboveTheFeaturePixelCap) {
  const EnlargedPair e = enlargedPair(bench::SweepScene::kRich, 15.0, 0.25, 2.6);
  ASSERT_GT(e.image1.total(), static_cast<size_t>(OrbOptions{}.max_pixels));
  const TwoViewResult r = estimateTwoView(e.image1, e.depth1, e.image2, e.depth2, e.camera, {});
  ASSERT_TRUE(r.ok) << r.failure;
  EXPECT_EQ(r.detector, "orb");
  expectNearTruth(r, e.rendered.T_21);
  float max_x = 0, max_y = 0;
  for (const cv::KeyPoint& k : r.keypoints1)
    max_x = std::max(max_x, k.pt.x), max_y = std::max(max_y, k.pt.y);
  EXPECT_GT(max_x, 0.9f * e.image1.cols);  // the image's pixels, not the shrunk copy's
  EXPECT_GT(max_y, 0.9f * e.image1.rows);
}

// A keypoint's sigma is its level's, in the pixels of the image it came from.
TEST(WorkingResolution, KeypointSigmaCountsTheShrink) {
  Features f;
  f.keypoints.emplace_back(cv::Point2f(10, 10), 31.0f, -1.0f, 0.0f, 2);
  TwoViewOptions options;
  EXPECT_DOUBLE_EQ(keypointSigma(f, 0, options), std::pow(1.2f, 2));
  f.pixel_scale = 1.5;
  EXPECT_DOUBLE_EQ(keypointSigma(f, 0, options), 1.5 * std::pow(1.2f, 2));
  options.weight_by_octave = false;
  EXPECT_DOUBLE_EQ(keypointSigma(f, 0, options), 1.5);
}

// The rich room at 60 degrees, which ORB cannot match and the SIFT retry recovers: at twice the
// resolution the retry starts at half of it and still recovers the pose.
TEST(WorkingResolution, SiftRetryHoldsAtTwiceTheResolution) {
  const EnlargedPair e = enlargedPair(bench::SweepScene::kRich, 60.0, 0.0);
  TwoViewOptions features_only;
  features_only.depth_path = DepthPath::kOff;
  const TwoViewOptions twice = siftRetryOptions(features_only, e.image1.size());
  EXPECT_EQ(twice.orb.sift_first_octave, 1);
  EXPECT_NEAR(twice.orb.sift_octave_fraction, kSiftRetryScale, 1e-9);  // of the halved image
  EXPECT_EQ(siftRetryOptions(features_only, e.rendered.view1.colour.size()).orb.sift_first_octave,
            0);
  // However large the image, a first octave SIFT's options accept.
  const TwoViewOptions huge = siftRetryOptions(features_only, {32000, 24000});
  EXPECT_EQ(huge.orb.sift_first_octave, 4);
  EXPECT_EQ(huge.validate(), "");
  expectSiftRecovers(e, features_only);
}

// ... and at 1.3 times it (832 x 624), where the retry's scale space starts at its share of 640 x
// 480's resolution: the image resampled by area, not halved.
TEST(WorkingResolution, SiftRetryHoldsAtAResolutionBetweenHalvings) {
  const EnlargedPair e = enlargedPair(bench::SweepScene::kRich, 60.0, 0.0, 1.3);
  TwoViewOptions features_only;
  features_only.depth_path = DepthPath::kOff;
  const TwoViewOptions retry = siftRetryOptions(features_only, e.image1.size());
  EXPECT_EQ(retry.orb.sift_first_octave, 0);
  EXPECT_NEAR(retry.orb.sift_octave_fraction, kSiftRetryScale * 640.0 / 832, 1e-9);
  EXPECT_EQ(
      siftRetryOptions(features_only, e.rendered.view1.colour.size()).orb.sift_octave_fraction,
      kSiftRetryScale);
  expectSiftRecovers(e, features_only);
}

// Twice the resolution, depth by nearest pixel: strided twice as far, the registration
// back-projects the very pixels it does at 640 x 480, so its clouds and voxel are the same.
TEST(WorkingResolution, RegistrationStridesALargerImageToTheSamePoints) {
  const EnlargedPair e = enlargedPair(bench::SweepScene::kPoor, 30.0, 1.0);
  DepthRegistrationOptions o;
  o.max_points = 0;  // the cap would hide how many pixels the stride keeps
  const DepthRegistration small = registerDepthImages(
      e.rendered.view1.depth, e.rendered.view2.depth, Camera().pinhole, Camera().depth_scale, o);
  const DepthRegistration large =
      registerDepthImages(e.depth1, e.depth2, e.camera.pinhole, e.camera.depth_scale, o);
  ASSERT_TRUE(small.ok) << small.failure;
  ASSERT_TRUE(large.ok) << large.failure;
  EXPECT_EQ(large.voxel_m, small.voxel_m);
  EXPECT_NEAR(large.points1, small.points1, 0.02 * small.points1);
  EXPECT_NEAR(large.points2, small.points2, 0.02 * small.points2);
  // Unscaled, the stride would sample the larger image as stride 2 samples the smaller one: the
  // points would be many more, so the checks above tell the two apart.
  DepthRegistrationOptions unstrided = o;
  unstrided.pixel_stride = 2;
  const DepthRegistration dense =
      registerDepthImages(e.rendered.view1.depth, e.rendered.view2.depth, Camera().pinhole,
                          Camera().depth_scale, unstrided);
  EXPECT_GT(dense.points1, 1.1 * small.points1);
}

// The registration under the default point cap of a pair whose cloud 1 exceeds it: the voxel
// grows until cloud 1 has about max_points, the coarse pose stays within a voxel-scale step of
// the truth (the depth path's alignment refines it), and the pipeline's pose is within 2 degrees
// and 5 cm.
void expectCappedRegistrationHolds(const SyntheticPair& p, const Camera& camera) {
  DepthRegistrationOptions unlimited;
  unlimited.max_points = 0;
  const DepthRegistration whole = registerDepthImages(p.view1.depth, p.view2.depth, camera.pinhole,
                                                      camera.depth_scale, unlimited);
  const DepthRegistrationOptions o;
  const DepthRegistration capped =
      registerDepthImages(p.view1.depth, p.view2.depth, camera.pinhole, camera.depth_scale, o);
  ASSERT_TRUE(capped.ok) << capped.failure;
  EXPECT_GT(whole.points1, o.max_points);
  EXPECT_LT(capped.points1, 1.2 * o.max_points);
  EXPECT_GT(capped.voxel_m, whole.voxel_m);
  EXPECT_LT(angleDeg(capped.T_21, p.T_21), 5.0);
  EXPECT_LT((capped.T_21.translation() - p.T_21.translation()).norm(), 0.25);
  const TwoViewResult r = estimateTwoView(p.view1.colour, p.view1.depth, p.view2.colour,
                                          p.view2.depth, camera, TwoViewOptions());
  ASSERT_TRUE(r.ok) << r.failure;
  expectNearTruth(r, p.T_21);
}

// A 93-degree 1280 x 720 view of the texture-poor room holds about three times the points of
// the cap.
TEST(WorkingResolution, RegistrationCoarsensItsVoxelForAWideView) {
  SyntheticPairOptions po = bench::wideBaselinePair(bench::SweepScene::kPoor, 30.0, 1.0, 0);
  po.camera = bench::sensorCamera("azure");
  const SyntheticPair p = renderSyntheticPair(po);
  ASSERT_EQ(p.view1.depth.size(), cv::Size(1280, 720));
  expectCappedRegistrationHolds(p, bench::estimationCamera(po.camera));
}

// Through the TUM camera the same room holds a little more than the cap at 10 cm.
TEST(WorkingResolution, RegistrationCoarsensARoomThroughATumCamera) {
  expectCappedRegistrationHolds(
      renderSyntheticPair(bench::wideBaselinePair(bench::SweepScene::kPoor, 30.0, 1.0, 0)),
      Camera());
}

}  // namespace
}  // namespace pnpba
