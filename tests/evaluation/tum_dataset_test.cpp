// TUM sequence reading on hand-made files with exact expected values, and the relative pose
// error against a hand-computed case.
#include "pnpba/evaluation/tum_dataset.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "pnpba/core/error.h"
#include "pnpba/evaluation/evaluation.h"
#include "scratch_dir.h"

namespace pnpba {
namespace {

namespace fs = std::filesystem;

std::string writeTemp(const std::string& name, const std::string& text) {
  const fs::path p = pnpba::test::scratchDir() / ("pnpba_tum_" + name);
  std::ofstream(p) << text;
  return p.string();
}

TEST(TumDataset, AssociatesNearestStampsWithinLimitOnce) {
  const std::vector<std::pair<double, std::string>> rgb = {
      {1.000, "rgb/a.png"}, {1.030, "rgb/b.png"}, {1.100, "rgb/c.png"}};
  const std::vector<std::pair<double, std::string>> depth = {
      {1.012, "depth/a.png"}, {1.026, "depth/b.png"}, {1.500, "depth/c.png"}};
  const std::vector<TumFrame> frames = associate(rgb, depth, 0.02);
  ASSERT_EQ(frames.size(), 2u);  // c has no depth within 0.02 s
  // b-b (0.004 s) is taken first, so a pairs with the remaining a (0.012 s).
  EXPECT_EQ(frames[0].rgb, "rgb/a.png");
  EXPECT_EQ(frames[0].depth, "depth/a.png");
  EXPECT_DOUBLE_EQ(frames[0].depth_stamp, 1.012);
  EXPECT_EQ(frames[1].rgb, "rgb/b.png");
  EXPECT_EQ(frames[1].depth, "depth/b.png");
}

TEST(TumDataset, ReadsListsAndAssociationsAndNamesBadLines) {
  const auto list = readStampedList(writeTemp("rgb.txt", "# color images\n1.5 rgb/1.5.png\n"));
  ASSERT_EQ(list.size(), 1u);
  EXPECT_DOUBLE_EQ(list[0].first, 1.5);
  const auto assoc = readAssociations(writeTemp("assoc.txt", "1.0 rgb/x.png 1.01 depth/x.png\n"));
  ASSERT_EQ(assoc.size(), 1u);
  EXPECT_EQ(assoc[0].depth, "depth/x.png");
  const std::string bad = writeTemp("bad.txt", "1.0 rgb/x.png 1.01\n");
  try {
    readAssociations(bad);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()), bad + ":1: expected 't_rgb rgb_path t_depth depth_path'");
  }
}

TEST(TumDataset, InterpolatesLinearlyAndBySlerp) {
  // Two samples 0.1 s apart: translation 0 -> (1, 2, 3), rotation 0 -> 90 deg about z.
  const std::string path = writeTemp("gt.txt",
                                     "# ground truth\n"
                                     "10.0 0 0 0 0 0 0 1\n"
                                     "10.1 1 2 3 0 0 0.70710678118654752 0.70710678118654752\n");
  const std::vector<StampedPose> gt = readTrajectory(path);
  const auto mid = interpolatePose(gt, 10.025);
  ASSERT_TRUE(mid.has_value());
  EXPECT_NEAR((mid->translation() - Eigen::Vector3d(0.25, 0.5, 0.75)).norm(), 0, 1e-12);
  const Eigen::AngleAxisd aa(mid->rotation());
  EXPECT_NEAR(aa.angle(), M_PI / 8, 1e-12);  // a quarter of 90 degrees
  EXPECT_NEAR(aa.axis().z(), 1.0, 1e-12);
  EXPECT_FALSE(interpolatePose(gt, 9.99).has_value());
  EXPECT_FALSE(interpolatePose(gt, 10.2).has_value());
  EXPECT_FALSE(interpolatePose(gt, 10.05, 0.05).has_value());  // neighbours 0.1 s apart
  EXPECT_TRUE(interpolatePose(gt, 10.1).has_value());          // exact stamp
}

TEST(TumDataset, RelativePoseAndErrorMatchAHandComputedCase) {
  // Camera 1 at the origin; camera 2 moved 1 m along x in the world, turned 90 deg about y.
  const SE3Quat T_wc1;
  const SE3Quat T_wc2(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()).toRotationMatrix(),
                      Eigen::Vector3d(1, 0, 0));
  const SE3Quat T_21 = relativePose(T_wc1, T_wc2);
  // A world point at (1, 0, 1) is 1 m in front of camera 2... along its -x axis:
  // X2 = R^T (X - c) = R_y(-90) (0, 0, 1) = (-1, 0, 0).
  EXPECT_NEAR((T_21.map(Eigen::Vector3d(1, 0, 1)) - Eigen::Vector3d(-1, 0, 0)).norm(), 0, 1e-12);
  // An estimate off by 2 degrees about z and by (3, 4, 0) cm.
  const SE3Quat estimate(
      Eigen::AngleAxisd(2 * M_PI / 180, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
          T_21.rotation().toRotationMatrix(),
      T_21.translation() + Eigen::Vector3d(0.03, 0.04, 0));
  const PoseError e = relativePoseError(estimate, T_21);
  EXPECT_NEAR(e.rot_deg, 2.0, 1e-9);
  EXPECT_NEAR(e.trans_cm, 5.0, 1e-9);
}

// The rounded rank p (n - 1): of 1 .. 20, rank 18.05 for p95 (the 19th value), 9.5 rounded up
// for the median (the 11th), the last for 1; nothing gives 0.
TEST(Evaluation, RankPercentileTakesTheRoundedRank) {
  std::vector<double> v;
  for (int k = 20; k >= 1; --k) v.push_back(k);  // unsorted on purpose
  EXPECT_DOUBLE_EQ(rankPercentile(v, 0.95), 19);
  EXPECT_DOUBLE_EQ(rankPercentile(v, 0.5), 11);
  EXPECT_DOUBLE_EQ(rankPercentile(v, 1.0), 20);
  EXPECT_DOUBLE_EQ(rankPercentile(v, 0.0), 1);
  EXPECT_DOUBLE_EQ(rankPercentile({}, 0.95), 0);
}

TEST(Evaluation, SummaryCountsFailuresAgainstSuccess) {
  std::vector<PairOutcome> o(4);
  o[0] = {true, {0.2, 0.5}, 10, false, {}};
  o[1] = {true, {0.6, 2.5}, 12, false, {}};  // solved but outside 2 cm
  o[2] = {true, {0.4, 1.0}, 11, false, {}};
  o[3] = {false, {}, 30, false, {}};
  const MethodSummary s = summarize(o);
  EXPECT_EQ(s.pairs, 4);
  EXPECT_EQ(s.failures, 1);
  EXPECT_DOUBLE_EQ(s.median_rot_deg, 0.4);
  EXPECT_DOUBLE_EQ(s.median_trans_cm, 1.0);
  EXPECT_DOUBLE_EQ(s.max_trans_cm, 2.5);
  EXPECT_DOUBLE_EQ(s.success_rate, 0.5);
  EXPECT_DOUBLE_EQ(s.median_time_ms, 11.5);
  // Times 10, 11, 12, 30: rank 0.95 x 3 = 2.85 rounds to the largest (the failed pair's).
  EXPECT_DOUBLE_EQ(s.p95_time_ms, 30);
  EXPECT_DOUBLE_EQ(s.max_time_ms, 30);
}

}  // namespace
}  // namespace pnpba

namespace pnpba {
namespace {

TEST(TumDataset, ReadsAKeyFrameFolderAndNamesBadLines) {
  const fs::path folder = pnpba::test::scratchDir() / "pnpba_keyframes";
  fs::remove_all(folder);
  fs::create_directories(folder / "rgb");
  fs::create_directories(folder / "depth");
  for (const char* f :
       {"rgb/0000.jpg", "depth/0000.png", "rgb/0001.png", "depth/0001.png", "rgb/0002.jpg"}) {
    std::ofstream(folder / f) << "x";
  }
  std::ofstream(folder / "poses.txt") << "# frame timestamp tx ty tz qx qy qz qw\n"
                                         "0000 10.5 1 2 3 0 0 0 1\n"
                                         "0001 11.0 1 2 4 0 0 0.7071068 0.7071068\n"
                                         "0002 11.5 0 0 0 0 0 0 1\n";  // its depth is missing
  const TumSequence seq = loadTumSequence(folder.string());
  ASSERT_EQ(seq.frames.size(), 2u);
  EXPECT_EQ(seq.frames_missing_files, 1);
  EXPECT_EQ(seq.frames[0].rgb, "rgb/0000.jpg");
  EXPECT_EQ(seq.frames[1].rgb, "rgb/0001.png");  // .png when there is no .jpg
  EXPECT_EQ(seq.frames[1].depth, "depth/0001.png");
  EXPECT_DOUBLE_EQ(seq.frames[1].rgb_stamp, 11.0);
  ASSERT_TRUE(seq.ground_truth[1]);
  EXPECT_NEAR(seq.ground_truth[1]->translation().z(), 4.0, 1e-12);
  // Frame 0 to frame 1: 1 m along z of the world and 90 degrees about z.
  const SE3Quat T_10 = relativePose(*seq.ground_truth[0], *seq.ground_truth[1]);
  EXPECT_NEAR(Eigen::AngleAxisd(T_10.rotation()).angle(), M_PI / 2, 1e-6);
  std::ofstream(folder / "poses.txt") << "0000 10.5 1 2 3 0 0 0\n";
  try {
    loadTumSequence(folder.string());
    FAIL() << "a short line must be refused";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("poses.txt:1: expected 'frame stamp"), std::string::npos)
        << e.what();
  }
  fs::remove_all(folder);
}

TEST(Evaluation, CountsTheWiderLimitsAndWrongPoses) {
  const std::vector<PairOutcome> outcomes = {
      {true, {0.5, 1.0}, 1, false, {}},  {true, {1.5, 4.0}, 1, false, {}},
      {true, {4.0, 15.0}, 1, false, {}}, {true, {12.0, 5.0}, 1, false, {}},
      {true, {1.0, 60.0}, 1, false, {}}, {false, {}, 1, false, {}}};
  const MethodSummary s = summarize(outcomes);
  EXPECT_EQ(s.within_2deg_5cm, 2);
  EXPECT_EQ(s.within_5deg_20cm, 3);
  EXPECT_EQ(s.wrong, 2);
  EXPECT_EQ(s.failures, 1);
}

// The NEES of an error a known number of sigmas along the covariance's axes: an error of
// (a, b) sigma along two axes has NEES a^2 + b^2, independently of the pose it is taken at.
TEST(Evaluation, CovarianceFitMeasuresTheErrorInSigmas) {
  const SE3Quat truth(
      Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized())),
      Eigen::Vector3d(0.4, -0.2, 1.1));
  Matrix6d C = Matrix6d::Zero();
  const double rot_sigma = 0.5 * M_PI / 180, trans_sigma = 0.02;  // per axis
  C.diagonal() << rot_sigma * rot_sigma, rot_sigma * rot_sigma, rot_sigma * rot_sigma,
      trans_sigma * trans_sigma, trans_sigma * trans_sigma, trans_sigma * trans_sigma;
  Eigen::Matrix<double, 6, 1> d = Eigen::Matrix<double, 6, 1>::Zero();
  d(2) = 2 * rot_sigma;    // 2 sigma about z
  d(3) = 3 * trans_sigma;  // 3 sigma along x
  const SE3Quat estimate = SE3Quat::exp(d) * truth;
  const CovarianceFit fit = covarianceFit(estimate, truth, C);
  EXPECT_NEAR(fit.nees, 4 + 9, 1e-6);
  EXPECT_FALSE(fit.inside95);  // 13 > 12.59
  // 1 deg against a reported 1-sigma of sqrt(3) * 0.5 deg; 6 cm against sqrt(3) * 2 cm.
  EXPECT_TRUE(fit.rot_within_2sigma);
  EXPECT_TRUE(fit.trans_within_2sigma);
  d(3) = 7 * trans_sigma;  // 14 cm > 2 * 3.46 cm
  const CovarianceFit far = covarianceFit(SE3Quat::exp(d) * truth, truth, C);
  EXPECT_FALSE(far.trans_within_2sigma);
  EXPECT_NEAR(far.nees, 4 + 49, 1e-6);

  std::vector<PairOutcome> o(3);
  o[0] = {true, {1, 6}, 10, true, fit};
  o[1] = {true, {1, 14}, 10, true, far};
  o[2] = {true, {0.1, 0.1}, 10, false, {}};  // no covariance: not counted
  const MethodSummary s = summarize(o);
  EXPECT_EQ(s.with_covariance, 2);
  EXPECT_NEAR(s.nees_median, (13 + 53) / 2.0, 1e-6);
  EXPECT_DOUBLE_EQ(s.nees_inside95, 0.0);
  EXPECT_DOUBLE_EQ(s.rot_within_2sigma, 1.0);
  EXPECT_DOUBLE_EQ(s.trans_within_2sigma, 0.5);
}

}  // namespace
}  // namespace pnpba
