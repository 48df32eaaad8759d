// The baselines evaluate_tum and latency_bench run beside pnpba: each must return the pose in
// pnpba's convention (T_21, camera 2 from camera 1) on an easy pair, or the comparison would
// count its right answers as wrong. Checked against the renderer's exact motion.
#include <gtest/gtest.h>

#include <sstream>

#include "pnpba/core/error.h"
#include "pnpba/core/plugin.h"
#include "pnpba/evaluation/evaluation.h"
#include "pnpba/evaluation/open3d_baseline.h"
#include "pnpba/evaluation/opencv_baseline.h"
#include "pnpba/evaluation/tum_evaluation.h"
#include "wide_baseline_pairs.h"

namespace pnpba {
namespace {

// The sweep's richly textured room, camera 2 turned 3 degrees and moved 5 cm (a pair either
// baseline settles), seen through the renderer's camera.
class Baselines : public ::testing::Test {
 protected:
  const SyntheticPair pair_ =
      renderSyntheticPair(bench::wideBaselinePair(bench::SweepScene::kRich, 3.0, 0.05, 0));
  const Camera camera_ = bench::estimationCamera(SyntheticCamera{});
};

TEST_F(Baselines, OpenCvReturnsCameraTwoFromCameraOne) {
  const TwoViewResult r =
      estimateTwoViewOpenCv(pair_.view1.colour, pair_.view1.depth, pair_.view2.colour, camera_, {});
  ASSERT_TRUE(r.ok) << r.failure;
  const PoseError e = relativePoseError(r.T_21, pair_.T_21);
  EXPECT_LT(e.rot_deg, 0.5);
  EXPECT_LT(e.trans_cm, 2.0);
  EXPECT_GT(r.times_ms.total_ms, 0.0);
}

TEST_F(Baselines, Open3dOdometryReturnsCameraTwoFromCameraOne) {
  const TwoViewResult r = estimateTwoViewOpen3dOdometry(
      pair_.view1.colour, pair_.view1.depth, pair_.view2.colour, pair_.view2.depth, camera_);
  ASSERT_TRUE(r.ok) << r.failure;
  EXPECT_TRUE(pluginLoaded("open3d_odometry"));
  const PoseError e = relativePoseError(r.T_21, pair_.T_21);
  EXPECT_LT(e.rot_deg, 0.5);
  EXPECT_LT(e.trans_cm, 2.0);
  // The inverse, camera 1 from camera 2, is twice the motion away: the test tells them apart.
  EXPECT_GT(relativePoseError(r.T_21.inverse(), pair_.T_21).rot_deg, 5.0);
  EXPECT_EQ(r.solver, "open3d-odometry");
  EXPECT_GT(r.times_ms.total_ms, 0.0);
}

TEST_F(Baselines, Open3dOdometryRejectsWhatThePipelineRejects) {
  const cv::Mat &image1 = pair_.view1.colour, &image2 = pair_.view2.colour;
  const cv::Mat &depth1 = pair_.view1.depth, &depth2 = pair_.view2.depth;
  EXPECT_THROW(estimateTwoViewOpen3dOdometry(image1, depth1, image2, cv::Mat(), camera_), Error);
  cv::Mat depth8;
  depth1.convertTo(depth8, CV_8U);
  EXPECT_THROW(estimateTwoViewOpen3dOdometry(image1, depth8, image2, depth2, camera_), Error);
  Open3dOdometryOptions bad;
  bad.max_depth = 0;
  EXPECT_THROW(estimateTwoViewOpen3dOdometry(image1, depth1, image2, depth2, camera_, bad), Error);
}

// A baseline's far-off pose (OpenCV's PnP returned translations of 1e13 cm on the wide
// fr3_cabinet pairs) keeps evaluate_tum's table in its columns: every row has as many fields
// as the header.
TEST(BaselinesTable, FarOffErrorsKeepTheTableInColumns) {
  TumEvaluation ev;
  ev.methods = {"rgbd", "opencv"};
  MethodSummary good;
  good.pairs = 45, good.median_rot_deg = 1.081, good.max_trans_cm = 5.049;
  MethodSummary far = good;
  far.median_rot_deg = 131.261, far.median_trans_cm = 7839.386;
  far.mean_trans_cm = 15538282027196.939, far.max_trans_cm = 62153128092968.164;
  ev.summaries = {{"rgbd", good}, {"opencv", far}};
  std::istringstream table(summaryTable(ev));
  auto fields = [](const std::string& line) {
    std::istringstream in(line);
    int n = 0;
    for (std::string field; in >> field;) ++n;
    return n;
  };
  std::string header, rgbd, opencv;
  std::getline(table, header), std::getline(table, rgbd), std::getline(table, opencv);
  // "med rot", "med cm", ..., "med ms", "p95 ms", "max ms", "NEES med": ten of two words
  const int columns = fields(header) - 10;
  EXPECT_EQ(fields(rgbd), columns);
  EXPECT_EQ(fields(opencv), columns);
  EXPECT_NE(opencv.find("1.55e+13"), std::string::npos) << opencv;
  EXPECT_EQ(rgbd.size(), opencv.size());
}

}  // namespace
}  // namespace pnpba
