// The default pipeline on real TUM fr1_desk pairs against ground truth, and the failure rule
// on pairs that share no rigid scene.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "pnpba/core/error.h"
#include "pnpba/evaluation/evaluation.h"
#include "pnpba/evaluation/tum_dataset.h"
#include "pnpba/pipeline/camera.h"
#include "pnpba/pipeline/two_view.h"
#include "shared_data.h"

namespace pnpba {
namespace {

Camera freiburg1() {
  Camera c;
  c.pinhole.fx = 517.3, c.pinhole.fy = 516.5, c.pinhole.cx = 318.6, c.pinhole.cy = 255.3;
  c.pinhole.distortion = {0.2624, -0.9531, -0.0054, 0.0026, 1.1633};
  return c;
}

class TumPairs : public ::testing::Test {
 protected:
  void SetUp() override {
    PNPBA_REQUIRE_SHARED_DATA();
    folder_ = test::sharedData("tum_fr1_desk");
    seq_ = loadTumSequence(folder_);
    ASSERT_EQ(seq_.frames.size(), 9u);
  }
  cv::Mat colour(int i) const { return cv::imread(folder_ + "/" + seq_.frames[i].rgb); }
  cv::Mat depth(int i) const {
    return cv::imread(folder_ + "/" + seq_.frames[i].depth, cv::IMREAD_UNCHANGED);
  }
  std::string folder_;
  TumSequence seq_;
};

// Bounds from the measured errors of the default pipeline on these pairs (0.41 deg / 0.45 cm,
// 0.65 deg / 0.79 cm, 0.27 deg / 0.20 cm) with a margin of about 1.5x: a change that makes the
// default pipeline clearly worse on real data fails.
TEST_F(TumPairs, DefaultPipelineStaysWithinMeasuredBounds) {
  struct Case {
    int i, j;
    double max_rot_deg, max_trans_cm;
  };
  for (const Case& c : {Case{0, 1, 0.62, 0.67}, Case{0, 3, 0.98, 1.2}, Case{4, 5, 0.4, 0.3}}) {
    const TwoViewResult r = estimateTwoView(colour(c.i), depth(c.i), colour(c.j), depth(c.j),
                                            freiburg1(), TwoViewOptions{});
    ASSERT_TRUE(r.ok) << r.failure;
    const PoseError e =
        relativePoseError(r.T_21, relativePose(*seq_.ground_truth[c.i], *seq_.ground_truth[c.j]));
    EXPECT_LT(e.rot_deg, c.max_rot_deg) << c.i << "-" << c.j;
    EXPECT_LT(e.trans_cm, c.max_trans_cm) << c.i << "-" << c.j;
  }
}

// Frames of two real scenes with both depths, as a relocalisation query of a place not seen
// brings them: the depth path runs (the registration finds some fit between any two clouds), and
// every such pair must be refused. fr1_desk's frames with the cabinet's key frames 0 and 20 (its
// richest, where the SIFT retry runs too), each way round under frame 1's camera. Measured: 60 of
// 60 such pairs refused (latency_bench --sets unrelated), where Open3D's RGB-D odometry returned
// a pose for all 60 and OpenCV's solvePnPRansac for 15.
TEST_F(TumPairs, FramesOfAnotherRealSceneAreRefusedWithBothDepths) {
  const std::string cabinet = test::sharedData("tum_fr3_cabinet_keyframes");
  const TumSequence other = loadTumSequence(cabinet);
  ASSERT_GE(other.frames.size(), 21u);
  const Camera fr3 = loadCameraYaml(std::string(PNPBA_SOURCE_DIR) + "/data/cameras/tum_fr3.yaml");
  for (int i : {0, 6}) {
    for (int k : {0, 20}) {
      const cv::Mat c = cv::imread(cabinet + "/" + other.frames[k].rgb);
      const cv::Mat d = cv::imread(cabinet + "/" + other.frames[k].depth, cv::IMREAD_UNCHANGED);
      const TwoViewResult desk_first =
          estimateTwoView(colour(i), depth(i), c, d, freiburg1(), TwoViewOptions{});
      EXPECT_FALSE(desk_first.ok) << "desk " << i << ", cabinet " << k << ": " << desk_first.path;
      EXPECT_FALSE(desk_first.failure.empty());
      const TwoViewResult cabinet_first =
          estimateTwoView(c, d, colour(i), depth(i), fr3, TwoViewOptions{});
      EXPECT_FALSE(cabinet_first.ok)
          << "cabinet " << k << ", desk " << i << ": " << cabinet_first.path;
      EXPECT_FALSE(cabinet_first.failure.empty());
    }
  }
}

TEST_F(TumPairs, PairsWithoutOverlapAreFailuresNotPoses) {
  const TwoViewOptions o;
  const cv::Mat c0 = colour(0), d0 = depth(0);
  // Two different scenes.
  const cv::Mat other = cv::imread(test::sharedData("slambook_ch7/1.png"));
  const TwoViewResult scenes = estimateTwoView(c0, d0, other, cv::Mat(), freiburg1(), o);
  EXPECT_FALSE(scenes.ok);
  // A mirrored frame: no rigid motion maps one onto the other.
  cv::Mat mirrored;
  cv::flip(colour(2), mirrored, 1);
  const TwoViewResult mirror = estimateTwoView(c0, d0, mirrored, cv::Mat(), freiburg1(), o);
  EXPECT_FALSE(mirror.ok) << "mirror gave a pose";
  // A 90-degree-rotated copy squeezed back to 640x480 (the one camera's size).
  cv::Mat rotated, squeezed;
  cv::rotate(c0, rotated, cv::ROTATE_90_CLOCKWISE);
  cv::resize(rotated(cv::Rect(0, 80, 480, 480)), squeezed, c0.size());
  const TwoViewResult rot = estimateTwoView(c0, d0, squeezed, cv::Mat(), freiburg1(), o);
  EXPECT_FALSE(rot.ok) << "rotated copy gave a pose";
  EXPECT_FALSE(rot.failure.empty());
}

TEST_F(TumPairs, RotatedCopyOfAnotherSizeIsAnInputError) {
  cv::Mat rotated;
  cv::rotate(colour(0), rotated, cv::ROTATE_90_CLOCKWISE);
  EXPECT_THROW(estimateTwoView(colour(0), depth(0), rotated, cv::Mat(), freiburg1(), {}), Error);
}

}  // namespace
}  // namespace pnpba
