// pose_estimation_3d2d as a user runs it: the sample pair against its ground truth, and every
// kind of bad input with its message and exit code (2 input, 1 estimation).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "cli_runner.h"
#include "pnpba/optimize/se3_quat.h"
#include "scratch_dir.h"

namespace {

namespace fs = std::filesystem;
using pnpba::test::CliRun;

const std::string kImages = std::string(PNPBA_SOURCE_DIR) + "/data/images/";
const std::string kImg1 = kImages + "1.png", kImg2 = kImages + "2.png",
                  kDepth1 = kImages + "1_depth.png", kDepth2 = kImages + "2_depth.png";

CliRun run(const std::string& args) { return pnpba::test::runCli(POSE_ESTIMATION_3D2D, args); }

std::string temp(const std::string& name) {
  return (pnpba::test::scratchDir() / ("pnpba_pe_" + name)).string();
}

std::string writeImage(const std::string& name, const cv::Mat& image) {
  const std::string path = temp(name);
  cv::imwrite(path, image);
  return path;
}

std::string args(const std::string& img1, const std::string& img2, const std::string& depth1,
                 const std::string& extra = "") {
  return img1 + " " + img2 + " " + depth1 + " --camera " + kImages + "camera.yaml " + extra;
}

TEST(PoseEstimationCli, SamplePairRecoversGroundTruthAndWritesJson) {
  const std::string json = temp("result.json");
  fs::remove(json);
  const CliRun r = run(args(kImg1, kImg2, kDepth1, kDepth2 + " --json " + json));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // Printed in the textbook's order.
  const size_t matches = r.out.find("matches"), pairs = r.out.find("3d-2d pairs"),
               inliers = r.out.find("inliers"), T = r.out.find("T=");
  EXPECT_LT(matches, pairs);
  EXPECT_LT(pairs, inliers);
  EXPECT_LT(inliers, T);
  const auto j = nlohmann::json::parse(pnpba::test::slurp(json));
  for (const char* key : {"T", "R_init", "t_init", "matches", "pairs", "inliers", "ba_mode",
                          "chi2_initial", "chi2_final", "covariance", "timings_ms"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  EXPECT_TRUE(j["timings_ms"].contains("total"));
  // Against data/images/T_21.txt (written by render_synthetic with the scene).
  std::ifstream truth_file(kImages + "T_21.txt");
  std::string comment;
  std::getline(truth_file, comment);
  Eigen::Matrix4d truth, got;
  for (int i = 0; i < 4; ++i)
    for (int k = 0; k < 4; ++k) {
      truth_file >> truth(i, k);
      got(i, k) = j["T"][i][k].get<double>();
    }
  const pnpba::SE3Quat Tt(truth.topLeftCorner<3, 3>(), truth.topRightCorner<3, 1>());
  const pnpba::SE3Quat Tg(got.topLeftCorner<3, 3>(), got.topRightCorner<3, 1>());
  EXPECT_LT((Tg * Tt.inverse()).log().head<3>().norm() * 180 / M_PI, 0.1);
  EXPECT_LT((Tg.translation() - Tt.translation()).norm(), 0.005);
}

TEST(PoseEstimationCli, MissingFile) {
  const CliRun r = run(args("/nonexistent/1.png", kImg2, kDepth1));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err, "pose_estimation_3d2d: /nonexistent/1.png: cannot open file\n");
}

TEST(PoseEstimationCli, UnreadableImage) {
  const std::string bad = temp("not_an_image.png");
  std::ofstream(bad) << "this is text";
  const CliRun r = run(args(kImg1, bad, kDepth1));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err, "pose_estimation_3d2d: " + bad + ": not an image OpenCV can decode\n");
}

TEST(PoseEstimationCli, DepthGivenAsColourImage) {
  // A 16-bit depth file where image 2 belongs: an error, not an image scaled to 8 bits.
  const CliRun r = run(args(kImg1, kDepth2, kDepth1));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err, "pose_estimation_3d2d: " + kDepth2 +
                       ": expected an 8-bit colour image, got 16-bit (a depth image?)\n");
}

TEST(PoseEstimationCli, EightBitDepth) {
  const std::string d = writeImage("depth8.png", cv::Mat(480, 640, CV_8UC1, cv::Scalar(100)));
  const CliRun r = run(args(kImg1, kImg2, d));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err, "pose_estimation_3d2d: " + d +
                       ": depth must be a 16-bit single-channel image (got 8-bit, 1 channel)\n");
}

TEST(PoseEstimationCli, ThreeChannelDepth) {
  const std::string d = writeImage("depth3.png", cv::Mat(480, 640, CV_16UC3, cv::Scalar::all(9)));
  const CliRun r = run(args(kImg1, kImg2, d));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err, "pose_estimation_3d2d: " + d +
                       ": depth must be a 16-bit single-channel image (got 16-bit, 3 channels)\n");
}

TEST(PoseEstimationCli, DepthSizeMismatch) {
  const std::string d = writeImage("small.png", cv::Mat(240, 320, CV_16UC1, cv::Scalar(5000)));
  const CliRun r = run(args(kImg1, kImg2, d));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err,
            "pose_estimation_3d2d: " + d + ": size 320x240 differs from " + kImg1 + "'s 640x480\n");
}

// Images of another size than the camera's calibration: the image and the camera file named, with
// both sizes.
TEST(PoseEstimationCli, ImagesOfAnotherSizeThanTheCamera) {
  // The sample pair with a row and a column more (a sensor mode of another size).
  cv::Mat colour(481, 641, CV_8UC3, cv::Scalar::all(0)), depth(481, 641, CV_16UC1, cv::Scalar(0));
  cv::imread(kImg1).copyTo(colour(cv::Rect(0, 0, 640, 480)));
  cv::imread(kDepth1, cv::IMREAD_UNCHANGED).copyTo(depth(cv::Rect(0, 0, 640, 480)));
  const std::string c = writeImage("wide.png", colour), d = writeImage("wide_depth.png", depth);
  const CliRun r = run(args(c, c, d));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err, "pose_estimation_3d2d: " + c + ": size 641x481 differs from " + kImages +
                       "camera.yaml's 640x480 (the size its intrinsics were calibrated at)\n");
}

TEST(PoseEstimationCli, AllZeroDepth) {
  const std::string d = writeImage("zero.png", cv::Mat(480, 640, CV_16UC1, cv::Scalar(0)));
  const CliRun r = run(args(kImg1, kImg2, d));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err, "pose_estimation_3d2d: " + d +
                       ": depth image has no valid depth (every value 0 or 65535)\n");
}

TEST(PoseEstimationCli, BlankImageHasNoKeypoints) {
  const std::string blank =
      writeImage("blank.png", cv::Mat(480, 640, CV_8UC3, cv::Scalar::all(128)));
  const CliRun r = run(args(kImg1, blank, kDepth1));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.err,
            "pose_estimation_3d2d: estimation failed: no keypoints in image 2 (no depth 2: the "
            "depth-only path could not run)\n");
}

TEST(PoseEstimationCli, UnrelatedImageGivesTooFewInliers) {
  cv::Mat noise(480, 640, CV_8UC3);
  cv::RNG rng(3);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 255);
  const std::string other = writeImage("noise.png", noise);
  const CliRun r = run(args(kImg1, other, kDepth1));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("required"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.rfind("pose_estimation_3d2d: estimation failed: ", 0), 0u) << r.err;
}

TEST(PoseEstimationCli, MalformedYaml) {
  const std::string yaml = temp("bad.yaml");
  std::ofstream(yaml) << "%YAML:1.0\nCamera.fx: 500\nCamera.fy: five hundred\n";
  const CliRun r = run(kImg1 + " " + kImg2 + " " + kDepth1 + " --camera " + yaml);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err,
            "pose_estimation_3d2d: " + yaml + ":3: Camera.fy: 'five hundred' is not a number\n");
}

TEST(PoseEstimationCli, NonNumericOption) {
  const CliRun r = run(args(kImg1, kImg2, kDepth1, "--features abc"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--features"), std::string::npos) << r.err;
}

TEST(PoseEstimationCli, NanIntrinsics) {
  const CliRun r = run(args(kImg1, kImg2, kDepth1, "--intrinsics nan,500,320,240"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err, "pose_estimation_3d2d: --intrinsics: 'nan' is not a finite number\n");
}

TEST(PoseEstimationCli, OutputInMissingFolderLeavesNothing) {
  const CliRun r = run(args(kImg1, kImg2, kDepth1, "--ply /nonexistent-dir/out.ply"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err, "pose_estimation_3d2d: /nonexistent-dir/out.ply: folder does not exist\n");
  EXPECT_FALSE(fs::exists("/nonexistent-dir"));
}

TEST(PoseEstimationCli, HelpExitsZero) {
  const CliRun r = run("--help");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("--preset"), std::string::npos);
}

}  // namespace

TEST(PoseEstimationCli, PrecisionLimitRefusesWithTheRuleNamedAndNoPose) {
  const std::string json = temp("limited.json");
  fs::remove(json);
  const CliRun r =
      run(args(kImg1, kImg2, kDepth1, kDepth2 + " --max-sigma-deg 0.0001 --json " + json));
  ASSERT_EQ(r.exit_code, 1) << r.out;
  EXPECT_NE(r.err.find("less precise than asked"), std::string::npos) << r.err;
  const auto j = nlohmann::json::parse(pnpba::test::slurp(json));
  EXPECT_FALSE(j["ok"].get<bool>());
  EXPECT_EQ(j["failure_rule"], "max_sigma");
  for (const char* key : {"T", "R_init", "t_init", "covariance"})
    EXPECT_FALSE(j.contains(key)) << key;
  // Without the limit the same pair is a pose, with its 1-sigma reported.
  const CliRun ok = run(args(kImg1, kImg2, kDepth1, kDepth2 + " --json " + json));
  ASSERT_EQ(ok.exit_code, 0) << ok.err;
  const auto k = nlohmann::json::parse(pnpba::test::slurp(json));
  EXPECT_TRUE(k["ok"].get<bool>());
  EXPECT_GT(k["sigma_deg"].get<double>(), 0.0);
}

// A time budget never cuts the feature path: the sample pair, which it settles alone, keeps its
// pose under the smallest budget; a negative budget is one line and exit 2.
TEST(PoseEstimationCli, ATimeBudgetLeavesAPoseTheFeaturesSettleAndRejectsANegativeOne) {
  const std::string json = temp("budget.json");
  fs::remove(json);
  ASSERT_EQ(run(args(kImg1, kImg2, kDepth1, kDepth2 + " --json " + json)).exit_code, 0);
  const auto free = nlohmann::json::parse(pnpba::test::slurp(json));
  ASSERT_EQ(free["path"], "features");
  fs::remove(json);
  const CliRun tight =
      run(args(kImg1, kImg2, kDepth1, kDepth2 + " --time-budget-ms 0.001 --json " + json));
  ASSERT_EQ(tight.exit_code, 0) << tight.err;
  const auto j = nlohmann::json::parse(pnpba::test::slurp(json));
  EXPECT_EQ(j["T"], free["T"]);

  const CliRun bad = run(args(kImg1, kImg2, kDepth1, "--time-budget-ms -1"));
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_EQ(bad.err, "pose_estimation_3d2d: time budget must be finite and >= 0 ms\n");
}

// The calibration's share of the 1-sigma is printed: its translation part recomputed from the
// JSON's sensitivity and the default sigmas (0.5 %, 1 px, 1 %), within the print's 3 digits; at
// most the whole; and no such line when the calibration is trusted exactly.
TEST(PoseEstimationCli, TheCalibrationsShareOfTheSigmaIsPrintedAsTheJsonSays) {
  const std::string json = temp("calibration.json");
  fs::remove(json);
  const CliRun r = run(args(kImg1, kImg2, kDepth1, kDepth2 + " --json " + json));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const size_t line = r.out.find("of which the calibration");
  ASSERT_NE(line, std::string::npos) << r.out;
  double share_deg = 0, share_cm = 0, total_deg = 0, total_cm = 0;
  ASSERT_EQ(std::sscanf(r.out.c_str() + r.out.find("): rotation", line),
                        "): rotation %lf deg, translation %lf cm", &share_deg, &share_cm),
            2);
  ASSERT_EQ(std::sscanf(r.out.c_str() + r.out.find("motion): rotation"),
                        "motion): rotation %lf deg, translation %lf cm", &total_deg, &total_cm),
            2);
  const auto j = nlohmann::json::parse(pnpba::test::slurp(json));
  Eigen::Matrix<double, 6, 5> S;
  for (int i = 0; i < 6; ++i)
    for (int k = 0; k < 5; ++k) S(i, k) = j["calibration_sensitivity"][i][k].get<double>();
  Eigen::Matrix<double, 5, 1> sigma;
  sigma << 0.005, 0.005, 1.0, 1.0, 0.01;
  const Eigen::Matrix<double, 6, 6> C = S * sigma.cwiseAbs2().asDiagonal() * S.transpose();
  const double expected_cm = 100 * std::sqrt(C.bottomRightCorner<3, 3>().trace());
  EXPECT_GT(expected_cm, 0.0);
  EXPECT_NEAR(share_cm, expected_cm, 0.006 * expected_cm + 1e-4);
  EXPECT_LE(share_cm, total_cm);
  EXPECT_LE(share_deg, total_deg);
  const CliRun exact = run(args(kImg1, kImg2, kDepth1,
                                kDepth2 + " --focal-sigma 0 --principal-point-sigma 0 "
                                          "--depth-scale-sigma 0"));
  ASSERT_EQ(exact.exit_code, 0) << exact.err;
  EXPECT_EQ(exact.out.find("of which the calibration"), std::string::npos) << exact.out;
}

TEST(PoseEstimationCli, JsonToStandardOutputIsParseableAndTheTextGoesToStderr) {
  for (const char* target : {"/dev/stdout", "-"}) {
    const CliRun r = run(args(kImg1, kImg2, kDepth1, kDepth2 + " --json " + target));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);  // throws if anything else is on stdout
    EXPECT_TRUE(j["ok"].get<bool>());
    EXPECT_NE(r.err.find("after optimization"), std::string::npos);
  }
}

TEST(PoseEstimationCli, JsonToAFullDeviceIsAnErrorAndTheDeviceSurvives) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full here";
  const CliRun r = run(args(kImg1, kImg2, kDepth1, kDepth2 + " --json /dev/full"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("/dev/full: write failed (No space left on device)"), std::string::npos)
      << r.err;
  EXPECT_TRUE(fs::is_character_file("/dev/full"));
}

TEST(PoseEstimationCli, TruncatedEmptyAndFolderImagesGetOneLineNamingTheFile) {
  const std::string truncated = temp("truncated.png"), empty = temp("empty.png");
  {
    const std::string whole = pnpba::test::slurp(kImg2);
    std::ofstream(truncated, std::ios::binary) << whole.substr(0, whole.size() / 3);
    std::ofstream(empty, std::ios::binary).flush();
  }
  const CliRun t = run(args(kImg1, truncated, kDepth1));
  EXPECT_EQ(t.exit_code, 2);
  EXPECT_EQ(t.err, "pose_estimation_3d2d: " + truncated + ": not an image OpenCV can decode\n");
  const CliRun e = run(args(kImg1, empty, kDepth1));
  EXPECT_EQ(e.err, "pose_estimation_3d2d: " + empty + ": empty file, not an image\n");
  const CliRun d = run(args(kImg1, kImg2, pnpba::test::scratchDir().string()));
  EXPECT_EQ(d.exit_code, 2);
  EXPECT_NE(d.err.find("is a folder, not an image"), std::string::npos) << d.err;
}

TEST(PoseEstimationCli, SiftDetectorRecoversTheSamplePoseAndSaysSo) {
  const std::string json = temp("sift.json");
  const CliRun r = run(args(kImg1, kImg2, kDepth1, kDepth2 + " --detector sift --json " + json));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(pnpba::test::slurp(json));
  EXPECT_EQ(j["detector"], "sift");
  EXPECT_EQ(j["path"], "features");
  // The same pose as ORB's to well within both 1-sigmas (about 0.05 deg, 0.3 cm).
  const CliRun orb = run(args(kImg1, kImg2, kDepth1, kDepth2 + " --json " + temp("orb.json")));
  ASSERT_EQ(orb.exit_code, 0) << orb.err;
  const auto o = nlohmann::json::parse(pnpba::test::slurp(temp("orb.json")));
  EXPECT_EQ(o["detector"], "orb");
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(j["T"][i][3].get<double>(), o["T"][i][3].get<double>(), 0.01) << i;
  }
  const CliRun bad = run(args(kImg1, kImg2, kDepth1, kDepth2 + " --detector surf"));
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("unknown detector 'surf'"), std::string::npos) << bad.err;
}

namespace {

// --verbose says where the time went: the stages that ran, with the JSON's figures.
TEST(PoseEstimationCli, VerboseReportsTheTimeOfEveryStageAsTheJsonDoes) {
  const std::string json = temp("verbose.json");
  const CliRun r = run(args(kImg1, kImg2, kDepth1, kDepth2 + " --verbose --json " + json));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const size_t at = r.out.find("time (ms): features ");
  ASSERT_NE(at, std::string::npos) << r.out;
  const std::string line = r.out.substr(at, r.out.find('\n', at) - at);
  const auto j = nlohmann::json::parse(pnpba::test::slurp(json));
  for (const auto& [key, name] : {std::pair<const char*, const char*>{"features", "features"},
                                  {"matching", "matching"},
                                  {"pnp", "pnp"},
                                  {"ba", "ba"},
                                  {"total", "total"}}) {
    const size_t p = line.find(std::string(name) + " ");
    ASSERT_NE(p, std::string::npos) << line;
    const double printed = std::stod(line.substr(p + std::string(name).size() + 1));
    EXPECT_NEAR(printed, j["timings_ms"][key].get<double>(), 0.051) << name << ": " << line;
  }
  EXPECT_EQ(line.find("registration"), std::string::npos) << line;  // it did not run
  fs::remove(json);
}

// A pair only the depths carry (a plain cabinet by a wall, 45 degrees round) runs the
// registration, which is pnpba's own: the run opens no Open3D (its ~100 libraries took 50-90 ms
// of such a run), and --verbose and the JSON show the registration's time and no opening.
TEST(PoseEstimationCli, ADepthPathPairOpensNoOpen3d) {
  const std::string dir = temp("plain_cabinet");
  fs::remove_all(dir);
  const pnpba::test::CliRun made = pnpba::test::runCli(
      RENDER_SYNTHETIC, "--output " + dir +
                            " --scene cabinet --texture poor --rotation-deg 45 --translation-m 1"
                            " --seed 1");
  ASSERT_EQ(made.exit_code, 0) << made.err;
  const std::string json = temp("plain_cabinet.json");
  const CliRun r = pnpba::test::runCli("LD_DEBUG=files " + std::string(POSE_ESTIMATION_3D2D),
                                       dir + "/1.png " + dir + "/2.png " + dir + "/1_depth.png " +
                                           dir + "/2_depth.png --camera " + dir +
                                           "/camera.yaml --verbose --json " + json);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err.find("libOpen3D"), std::string::npos);
  EXPECT_EQ(r.err.find("libpnpba_open3d.so"), std::string::npos);
  const auto j = nlohmann::json::parse(pnpba::test::slurp(json));
  ASSERT_EQ(j["path"], "depth-registration") << j.dump();
  const auto& t = j["timings_ms"];
  EXPECT_EQ(t["plugin_load"].get<double>(), 0.0) << t.dump();
  EXPECT_GT(t["registration"].get<double>(), 0.0) << t.dump();
  EXPECT_LE(t["registration"].get<double>(), t["total"].get<double>()) << t.dump();
  const size_t at = r.out.find("time (ms): ");
  ASSERT_NE(at, std::string::npos) << r.out;
  const std::string line = r.out.substr(at, r.out.find('\n', at) - at);
  const size_t p = line.find("registration ");
  ASSERT_NE(p, std::string::npos) << line;
  EXPECT_NEAR(std::stod(line.substr(p + 13)), t["registration"].get<double>(), 0.051) << line;
  EXPECT_EQ(line.find("plugin_load"), std::string::npos) << line;  // nothing opened
  fs::remove_all(dir);
  fs::remove(json);
}

}  // namespace
