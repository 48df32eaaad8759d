// evaluate_tum as a user runs it on the shared fr1_desk frames: table, JSON schema, CSV, plot,
// trajectory; bad input with its message and exit code.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "cli_runner.h"
#include "scratch_dir.h"
#include "shared_data.h"

namespace {

namespace fs = std::filesystem;
using pnpba::test::CliRun;

CliRun run(const std::string& args) { return pnpba::test::runCli(EVALUATE_TUM, args); }

std::string temp(const std::string& name) {
  return (pnpba::test::scratchDir() / ("pnpba_eval_" + name)).string();
}

TEST(EvaluateTumCli, WritesEveryOutputForConsecutivePairs) {
  PNPBA_REQUIRE_SHARED_DATA();
  const std::string json = temp("r.json"), csv = temp("r.csv"), plot = temp("r.png"),
                    traj = temp("traj.txt");
  for (const auto& f : {json, csv, plot, traj}) fs::remove(f);
  const CliRun r =
      run(pnpba::test::sharedData("tum_fr1_desk") + " --max-gap 1 --methods rgbd,opencv --json " +
          json + " --csv " + csv + " --plot " + plot + " --trajectory " + traj);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // The camera is said first: the folder's name (tum_fr1_desk) names freiburg1.
  EXPECT_EQ(r.out.rfind("camera: TUM freiburg1 (named by the folder)\n", 0), 0u) << r.out;
  EXPECT_NE(r.out.find("pair   0-  1:"), std::string::npos);
  EXPECT_NE(r.out.find("med rot"), std::string::npos);
  const auto j = nlohmann::json::parse(pnpba::test::slurp(json));
  EXPECT_EQ(j["camera"], "TUM freiburg1 (named by the folder)");
  for (const char* m : {"rgbd", "opencv"}) {
    ASSERT_TRUE(j["methods"].contains(m));
    for (const char* key :
         {"median_rot_deg", "median_trans_cm", "mean_rot_deg", "mean_trans_cm", "success_rate",
          "failures", "pairs", "median_time_ms", "p95_time_ms", "max_time_ms"}) {
      EXPECT_TRUE(j["methods"][m].contains(key)) << m << " " << key;
    }
    EXPECT_EQ(j["methods"][m]["pairs"], 8);  // 9 frames, k = 1
  }
  EXPECT_EQ(j["pairs"].size(), 8u);
  // The summary's slowest pair is the slowest of the per-pair records, its p95 no faster than
  // its median.
  double slowest = 0;
  for (const auto& p : j["pairs"]) slowest = std::max(slowest, p["rgbd"]["time_ms"].get<double>());
  EXPECT_DOUBLE_EQ(j["methods"]["rgbd"]["max_time_ms"].get<double>(), slowest);
  EXPECT_LE(j["methods"]["rgbd"]["median_time_ms"].get<double>(),
            j["methods"]["rgbd"]["p95_time_ms"].get<double>());
  // Consecutive fr1_desk frames: the default pipeline stays well inside 1 deg / 2 cm.
  EXPECT_LT(j["methods"]["rgbd"]["median_rot_deg"].get<double>(), 1.0);
  EXPECT_LT(j["methods"]["rgbd"]["median_trans_cm"].get<double>(), 2.0);
  const cv::Mat png = cv::imread(plot);
  EXPECT_FALSE(png.empty());
  // 9 trajectory lines after the comment, the first at frame 0's ground truth.
  const std::string t = pnpba::test::slurp(traj);
  EXPECT_EQ(std::count(t.begin(), t.end(), '\n'), 10);
  const std::string rows = pnpba::test::slurp(csv);
  EXPECT_EQ(std::count(rows.begin(), rows.end(), '\n'), 17);  // header + 8 pairs x 2 methods
}

TEST(EvaluateTumCli, BadInputIsExit2) {
  EXPECT_EQ(run("/nonexistent-sequence").err,
            "evaluate_tum: /nonexistent-sequence: not a folder\n");
  PNPBA_REQUIRE_SHARED_DATA();
  const CliRun r = run(pnpba::test::sharedData("tum_fr1_desk") + " --methods rgbd,orb-slam");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err,
            "evaluate_tum: methods: unknown method 'orb-slam' (BA modes none, pose, textbook, "
            "two-camera, rgbd; baselines opencv, open3d)\n");
}

}  // namespace

namespace {

TEST(EvaluateTumCli, JsonToStandardOutputIsParseableAndTheTableGoesToStderr) {
  PNPBA_REQUIRE_SHARED_DATA();
  const CliRun r = run(pnpba::test::sharedData("tum_fr1_desk") +
                       " --max-gap 1 --methods rgbd --json /dev/stdout");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_TRUE(j["methods"].contains("rgbd"));
  EXPECT_NE(r.err.find("sequence"), std::string::npos);
}

}  // namespace
