// Features found once per frame (describeFrame) against the estimate that finds its own: the same
// answer to the bit, and a clear error for features of another image or other options. The SIFT
// retry's features of a given frame, and its depth's description for the registration as frame
// 1, are kept in it for its next pairs, with the same answers.
#include "pnpba/pipeline/frame_features.h"

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <thread>

#include "pnpba/core/error.h"
#include "pnpba/pipeline/depth_registration.h"
#include "pnpba/pipeline/two_view.h"
#include "pnpba/synthetic/synthetic_scene.h"
#include "shared_data.h"
#include "two_view_stages.h"
#include "wide_baseline_pairs.h"

namespace pnpba {
namespace {

struct Frames {
  cv::Mat image1, depth1, image2, depth2;
  Camera camera;
};

Frames render() {
  Frames f;
  f.camera.width = 640;
  f.camera.height = 480;
  const SyntheticScene scene(7);
  const SyntheticCamera render_camera{f.camera.pinhole, 640, 480, f.camera.depth_scale};
  const RenderedView v1 = scene.render(render_camera, SE3Quat(), DepthNoise{}, 8);
  const RenderedView v2 =
      scene.render(render_camera, SyntheticScene::defaultMotion(), DepthNoise{}, 9);
  f.image1 = v1.colour, f.depth1 = v1.depth, f.image2 = v2.colour, f.depth2 = v2.depth;
  return f;
}

// Rendered once for every test here.
const Frames& renderedPair() {
  static const Frames frames = render();
  return frames;
}

void expectSameAnswer(const TwoViewResult& a, const TwoViewResult& b, const std::string& what) {
  ASSERT_EQ(a.ok, b.ok) << what;
  EXPECT_EQ(a.path, b.path) << what;
  EXPECT_EQ(a.detector, b.detector) << what;
  EXPECT_EQ(a.failure, b.failure) << what;
  EXPECT_EQ(a.counts.keypoints1, b.counts.keypoints1) << what;
  EXPECT_EQ(a.counts.keypoints2, b.counts.keypoints2) << what;
  EXPECT_EQ(a.counts.matches, b.counts.matches) << what;
  EXPECT_EQ(a.counts.inliers, b.counts.inliers) << what;
  EXPECT_EQ(a.T_21.to_homogeneous_matrix(), b.T_21.to_homogeneous_matrix()) << what;
  EXPECT_EQ(a.covariance, b.covariance) << what;
}

// The estimate given both frames' features, image 1's alone and image 2's alone, against `own`.
void expectTheSameAnswerGiven(const TwoViewResult& own, const Frames& f, const TwoViewOptions& o,
                              const FrameFeatures& first, const FrameFeatures& second,
                              const std::string& what) {
  expectSameAnswer(
      own, estimateTwoView(f.image1, f.depth1, f.image2, f.depth2, f.camera, o, &first, &second),
      what + ": both given");
  expectSameAnswer(
      own, estimateTwoView(f.image1, f.depth1, f.image2, f.depth2, f.camera, o, &first, nullptr),
      what + ": image 1's given");
  expectSameAnswer(
      own, estimateTwoView(f.image1, f.depth1, f.image2, f.depth2, f.camera, o, nullptr, &second),
      what + ": image 2's given");
}

// The estimate given either image's features, or both, against the one that finds both.
void expectGivenFeaturesChangeNothing(const Frames& f, const TwoViewOptions& o) {
  const TwoViewResult own = estimateTwoView(f.image1, f.depth1, f.image2, f.depth2, f.camera, o);
  expectTheSameAnswerGiven(own, f, o, describeFrame(f.image1, o.orb),
                           describeFrame(f.image2, o.orb), "described");
}

TEST(FrameFeatures, GivenFeaturesGiveTheSameAnswerOnARenderedPair) {
  const Frames& f = renderedPair();
  const TwoViewOptions o;
  expectGivenFeaturesChangeNothing(f, o);
  const TwoViewResult r = estimateTwoView(f.image1, f.depth1, f.image2, f.depth2, f.camera, o);
  EXPECT_TRUE(r.ok) << r.failure;  // a pose to compare, not a refusal
  // ORB settles the pair: nothing else is found, so nothing more is kept.
  const FrameFeatures first = describeFrame(f.image1, o.orb);
  estimateTwoView(f.image1, f.depth1, f.image2, f.depth2, f.camera, o, &first);
  EXPECT_EQ(first.later->size(), 0u);
}

// The wide-baseline sweep's rich room at 60 degrees, 0 m, its first seed: ORB's matches run out
// and the SIFT retry finds the pose.
Frames retriedPair() {
  const SyntheticPair p =
      renderSyntheticPair(bench::wideBaselinePair(bench::SweepScene::kRich, 60.0, 0.0, 0));
  Frames f;
  f.image1 = p.view1.colour, f.depth1 = p.view1.depth;
  f.image2 = p.view2.colour, f.depth2 = p.view2.depth;
  return f;
}

void expectSameFeatures(const Features& a, const Features& b) {
  ASSERT_EQ(a.keypoints.size(), b.keypoints.size());
  for (size_t i = 0; i < a.keypoints.size(); ++i) {
    EXPECT_EQ(a.keypoints[i].pt, b.keypoints[i].pt) << i;
    EXPECT_EQ(a.keypoints[i].octave, b.keypoints[i].octave) << i;
  }
  ASSERT_EQ(a.descriptors.size(), b.descriptors.size());
  EXPECT_EQ(cv::norm(a.descriptors, b.descriptors, cv::NORM_INF), 0.0);
}

TEST(FrameFeatures, TheSiftRetrysFeaturesAreKeptForTheFramesNextPairs) {
  const Frames f = retriedPair();
  const TwoViewOptions o;
  const TwoViewResult own = estimateTwoView(f.image1, f.depth1, f.image2, f.depth2, f.camera, o);
  ASSERT_GT(own.times_ms.sift_retry_ms, 0.0) << "the retry did not run; nothing is exercised";
  EXPECT_EQ(own.detector, "sift");

  const FrameFeatures first = describeFrame(f.image1, o.orb);
  const FrameFeatures second = describeFrame(f.image2, o.orb);
  const FrameFeatures copy_of_first = first;  // shares what the estimates keep
  EXPECT_EQ(first.later->size(), 0u);
  // The retry finds both frames' SIFT features and keeps them: the same answer.
  expectSameAnswer(
      own, estimateTwoView(f.image1, f.depth1, f.image2, f.depth2, f.camera, o, &first, &second),
      "the retry's features found");
  ASSERT_EQ(first.later->size(), 1u);
  ASSERT_EQ(second.later->size(), 1u);
  EXPECT_EQ(copy_of_first.later->size(), 1u);
  // What is kept is what the retry finds in that image.
  const OrbOptions retry = siftRetryOptions(o, f.image1.size()).orb;
  const std::optional<Features> kept1 = first.later->find(retry);
  ASSERT_TRUE(kept1.has_value());
  expectSameFeatures(*kept1, detectOrb(f.image1, retry));
  EXPECT_FALSE(first.later->find(o.orb).has_value());  // the frame's own are not in it
  // The next pairs take them, whichever side the frame is on: the same answer.
  expectTheSameAnswerGiven(own, f, o, first, second, "the retry's features taken");
  EXPECT_EQ(first.later->size(), 1u);

  // Two estimates at once on fresh frames: each answers the same, and one copy is kept.
  const FrameFeatures fresh1 = describeFrame(f.image1, o.orb);
  const FrameFeatures fresh2 = describeFrame(f.image2, o.orb);
  TwoViewResult a, b;
  std::thread one([&] {
    a = estimateTwoView(f.image1, f.depth1, f.image2, f.depth2, f.camera, o, &fresh1, &fresh2);
  });
  std::thread other([&] {
    b = estimateTwoView(f.image1, f.depth1, f.image2, f.depth2, f.camera, o, &fresh1, &fresh2);
  });
  one.join();
  other.join();
  expectSameAnswer(own, a, "at once, one");
  expectSameAnswer(own, b, "at once, the other");
  EXPECT_EQ(fresh1.later->size(), 1u);
  EXPECT_EQ(fresh2.later->size(), 1u);
}

// The rendered cabinet by a wall seen from its sweep's key frame (the first seed's 0-degree,
// 0 m cell's frame 1) after the motion of the cell at deg, metres: too little texture for the
// features, so the depth registration runs.
Frames fromCabinetKeyFrame(double deg, double metres) {
  SyntheticPairOptions o = bench::wideBaselinePair(bench::SweepScene::kCabinet, deg, metres, 0);
  o.seed = bench::wideBaselinePair(bench::SweepScene::kCabinet, 0.0, 0.0, 0).seed;
  const SyntheticPair p = renderSyntheticPair(o);
  Frames f;
  f.image1 = p.view1.colour, f.depth1 = p.view1.depth;
  f.image2 = p.view2.colour, f.depth2 = p.view2.depth;
  return f;
}

void expectSameRegistration(const DepthRegistration& a, const DepthRegistration& b,
                            const std::string& what) {
  ASSERT_EQ(a.ok, b.ok) << what;
  EXPECT_EQ(a.failure, b.failure) << what;
  EXPECT_EQ(a.T_21.to_homogeneous_matrix(), b.T_21.to_homogeneous_matrix()) << what;
  ASSERT_EQ(a.candidates.size(), b.candidates.size()) << what;
  for (size_t k = 0; k < a.candidates.size(); ++k) {
    EXPECT_EQ(a.candidates[k].T_21.to_homogeneous_matrix(),
              b.candidates[k].T_21.to_homogeneous_matrix())
        << what << ", candidate " << k;
    EXPECT_EQ(a.candidates[k].fitness, b.candidates[k].fitness) << what << ", candidate " << k;
  }
  EXPECT_EQ(a.fitness, b.fitness) << what;
  EXPECT_EQ(a.inlier_rmse, b.inlier_rmse) << what;
  EXPECT_EQ(a.points1, b.points1) << what;
  EXPECT_EQ(a.points2, b.points2) << what;
  EXPECT_EQ(a.voxel_m, b.voxel_m) << what;
}

TEST(FrameFeatures, AKeyFramesDepthDescriptionIsKeptForItsNextRegistrations) {
  const Frames near = fromCabinetKeyFrame(10.0, 0.25), far = fromCabinetKeyFrame(30.0, 0.5);
  ASSERT_EQ(cv::norm(near.depth1, far.depth1, cv::NORM_INF), 0.0) << "not one key frame";
  const Camera camera;
  const PinholeCamera& k = camera.pinhole;
  const double scale = camera.depth_scale;
  const DepthRegistrationOptions o;
  const DepthRegistration own_near = registerDepthImages(near.depth1, near.depth2, k, scale, o);
  const DepthRegistration own_far = registerDepthImages(far.depth1, far.depth2, k, scale, o);
  ASSERT_TRUE(own_near.ok) << own_near.failure;
  EXPECT_FALSE(own_near.depth1_described_before);

  LaterFeatures kept;
  const DepthRegistration first = registerDepthImages(near.depth1, near.depth2, k, scale, o, &kept);
  EXPECT_FALSE(first.depth1_described_before);
  EXPECT_EQ(kept.depthSize(), 1u);
  expectSameRegistration(own_near, first, "the key frame described");
  // The next registrations from the key frame take its description: the same registrations.
  const DepthRegistration second = registerDepthImages(far.depth1, far.depth2, k, scale, o, &kept);
  EXPECT_TRUE(second.depth1_described_before);
  expectSameRegistration(own_far, second, "its description taken");
  const DepthRegistration again = registerDepthImages(near.depth1, near.depth2, k, scale, o, &kept);
  EXPECT_TRUE(again.depth1_described_before);
  expectSameRegistration(own_near, again, "its description taken again");
  EXPECT_EQ(kept.depthSize(), 1u);

  // Another option the description follows, another camera or another pixel of depth 1 is
  // another description: made (the same registration as without the store) and kept apart.
  DepthRegistrationOptions fewer = o;
  fewer.fpfh_neighbours = 50;
  const DepthRegistration other_options =
      registerDepthImages(far.depth1, far.depth2, k, scale, fewer, &kept);
  EXPECT_FALSE(other_options.depth1_described_before);
  expectSameRegistration(registerDepthImages(far.depth1, far.depth2, k, scale, fewer),
                         other_options, "other options");
  PinholeCamera other_camera = k;
  other_camera.cx += 0.5;
  EXPECT_FALSE(registerDepthImages(far.depth1, far.depth2, other_camera, scale, o, &kept)
                   .depth1_described_before);
  cv::Mat other_depth = far.depth1.clone();
  other_depth.at<uint16_t>(240, 320) += 1;
  EXPECT_FALSE(
      registerDepthImages(other_depth, far.depth2, k, scale, o, &kept).depth1_described_before);
  EXPECT_EQ(kept.depthSize(), 4u);
  // The store is full: a fifth is made and not kept.
  other_depth.at<uint16_t>(240, 320) += 1;
  EXPECT_FALSE(
      registerDepthImages(other_depth, far.depth2, k, scale, o, &kept).depth1_described_before);
  EXPECT_EQ(kept.depthSize(), LaterFeatures::kMaxKept);
}

TEST(FrameFeatures, AKeyFramesDepthDescriptionGivesTheSameAnswers) {
  const Frames near = fromCabinetKeyFrame(10.0, 0.25), far = fromCabinetKeyFrame(30.0, 0.5);
  const TwoViewOptions o;
  const TwoViewResult own_near =
      estimateTwoView(near.image1, near.depth1, near.image2, near.depth2, near.camera, o);
  const TwoViewResult own_far =
      estimateTwoView(far.image1, far.depth1, far.image2, far.depth2, far.camera, o);
  ASSERT_GT(own_near.times_ms.registration_ms, 0.0) << "no registration; nothing is exercised";
  ASSERT_GT(own_far.times_ms.registration_ms, 0.0) << "no registration; nothing is exercised";

  const FrameFeatures key = describeFrame(near.image1, o.orb);
  expectSameAnswer(
      own_near,
      estimateTwoView(near.image1, near.depth1, near.image2, near.depth2, near.camera, o, &key),
      "the key frame's depth described");
  EXPECT_EQ(key.later->depthSize(), 1u);
  // Two estimates at once take it: the same answers.
  const FrameFeatures far2 = describeFrame(far.image2, o.orb);
  TwoViewResult a, b;
  std::thread one([&] {
    a = estimateTwoView(far.image1, far.depth1, far.image2, far.depth2, far.camera, o, &key, &far2);
  });
  std::thread other([&] {
    b = estimateTwoView(near.image1, near.depth1, near.image2, near.depth2, near.camera, o, &key);
  });
  one.join();
  other.join();
  expectSameAnswer(own_far, a, "its description taken, at once, one");
  expectSameAnswer(own_near, b, "its description taken, at once, the other");
  EXPECT_EQ(key.later->depthSize(), 1u);
  EXPECT_EQ(far2.later->depthSize(), 0u);  // frame 2's depth is described at frame 1's voxel
}

TEST(FrameFeatures, LaterFeaturesKeepTheFirstOfEachOptionsAndFewOptions) {
  const Frames& f = renderedPair();
  LaterFeatures later;
  OrbOptions o;
  const Features found = detectOrb(f.image1, o);
  later.keep(o, found);
  EXPECT_EQ(later.size(), 1u);
  later.keep(o, Features{});  // the same options again: the first stays
  ASSERT_TRUE(later.find(o).has_value());
  EXPECT_EQ(later.find(o)->keypoints.size(), found.keypoints.size());
  for (int n = 1; n <= 10; ++n) {
    o.num_features = 100 * n;
    later.keep(o, Features{});
  }
  EXPECT_EQ(later.size(), LaterFeatures::kMaxKept);
  // A copy of what was kept: writing into the found descriptors (which share their buffer with
  // every shallow copy) leaves it as it was.
  const cv::Mat before = found.descriptors.clone();
  Features changed = found;
  changed.descriptors.setTo(0);
  EXPECT_EQ(cv::norm(later.find(OrbOptions{})->descriptors, before, cv::NORM_INF), 0.0);
}

TEST(FrameFeatures, GivenFeaturesGiveTheSameAnswerOnRealFrames) {
  PNPBA_REQUIRE_SHARED_DATA();
  const std::string d = test::sharedData("slambook_ch7/");
  Frames f;
  f.image1 = cv::imread(d + "1.png", cv::IMREAD_COLOR);
  f.image2 = cv::imread(d + "2.png", cv::IMREAD_COLOR);
  f.depth1 = cv::imread(d + "1_depth.png", cv::IMREAD_UNCHANGED);
  f.depth2 = cv::imread(d + "2_depth.png", cv::IMREAD_UNCHANGED);
  ASSERT_FALSE(f.image1.empty());
  expectGivenFeaturesChangeNothing(f, TwoViewOptions());
  expectGivenFeaturesChangeNothing(f, TwoViewOptions::textbookPreset());
}

TEST(FrameFeatures, FeaturesOfAnotherImageAreRefused) {
  const Frames& f = renderedPair();
  const TwoViewOptions o;
  const FrameFeatures first = describeFrame(f.image1, o.orb);
  try {
    estimateTwoView(f.image1, f.depth1, f.image2, f.depth2, f.camera, o, &first, &first);
    FAIL() << "image 1's features taken for image 2's";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "image 2: its frame features were found in another image");
  }
  // One pixel changed is another image.
  cv::Mat touched = f.image1.clone();
  touched.at<cv::Vec3b>(240, 320)[1] ^= 1;
  EXPECT_THROW(estimateTwoView(touched, f.depth1, f.image2, f.depth2, f.camera, o, &first), Error);
}

TEST(FrameFeatures, FeaturesFoundWithOtherOptionsAreRefused) {
  const Frames& f = renderedPair();
  TwoViewOptions o;
  OrbOptions fewer = o.orb;
  fewer.num_features = 1000;
  const FrameFeatures first = describeFrame(f.image1, fewer);
  try {
    estimateTwoView(f.image1, f.depth1, f.image2, f.depth2, f.camera, o, &first);
    FAIL() << "features of 1000 taken for 1500";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(),
                 "image 1: its frame features were found with other feature options than this "
                 "estimate's");
  }
  o.orb = fewer;  // the same options: accepted
  EXPECT_NO_THROW(estimateTwoView(f.image1, f.depth1, f.image2, f.depth2, f.camera, o, &first));
}

TEST(ImageFingerprint, FollowsThePixelsNotTheMemoryLayout) {
  const Frames& f = renderedPair();
  const cv::Mat window = f.image1(cv::Rect(3, 5, 101, 77));  // rows apart in memory
  EXPECT_EQ(imageFingerprint(window), imageFingerprint(window.clone()));
  EXPECT_NE(imageFingerprint(window), imageFingerprint(f.image1(cv::Rect(4, 5, 101, 77))));
  EXPECT_NE(imageFingerprint(f.image1), imageFingerprint(f.image2));
  // The same bytes as another shape or type are another image.
  const cv::Mat grey(4, 6, CV_8UC1, cv::Scalar(9));
  EXPECT_NE(imageFingerprint(grey), imageFingerprint(grey.reshape(1, 6)));
  EXPECT_NE(imageFingerprint(grey), imageFingerprint(grey.reshape(2, 4)));
}

}  // namespace
}  // namespace pnpba
