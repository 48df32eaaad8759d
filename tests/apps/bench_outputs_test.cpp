// The benches' output files as a user meets them (DESIGN.md section 5, bench/bench_output.h): a
// path that cannot be written is one line and exit 2 before any work; a file is written whole,
// through a symbolic link into its target, with no temporary left beside it.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "cli_runner.h"
#include "scratch_dir.h"

namespace {

namespace fs = std::filesystem;
using pnpba::test::CliRun;
using pnpba::test::runCli;

struct Bench {
  std::string name, program;
};

TEST(BenchOutputs, AnUnwritablePathStopsEveryBenchBeforeItsWork) {
  const std::string missing = "/nonexistent-pnpba-folder/out.json";
  const std::vector<Bench> benches = {{"latency_bench", LATENCY_BENCH},
                                      {"wide_baseline_bench", WIDE_BASELINE_BENCH},
                                      {"covariance_bench", COVARIANCE_BENCH},
                                      {"bal_bench", BAL_BENCH}};
  for (const Bench& b : benches) {
    for (const std::string option : {"--json", "--plot"}) {
      SCOPED_TRACE(b.name + " " + option);
      const CliRun r = runCli(b.program, option + " " + missing);
      EXPECT_EQ(r.exit_code, 2);
      EXPECT_EQ(r.err, b.name + ": " + missing + ": folder does not exist\n");
      EXPECT_EQ(r.out, "");  // no table printed: no work began
    }
  }
  const CliRun r = runCli(COVARIANCE_BENCH, "--poses " + missing);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err, "covariance_bench: " + missing + ": folder does not exist\n");
}

// orbit_bench: a path it cannot write stops it before its work; its JSON counts every pair once
// per angle, and the cabinet seen from where camera 1 stands is estimated right.
TEST(BenchOutputs, OrbitBenchCountsEveryPairOnce) {
  const std::string missing = "/nonexistent-pnpba-folder/out.json";
  const CliRun bad = runCli(ORBIT_BENCH, "--json " + missing);
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_EQ(bad.err, "orbit_bench: " + missing + ": folder does not exist\n");
  EXPECT_EQ(bad.out, "");

  const fs::path json = pnpba::test::scratchPath("pnpba_orbit.json");
  const CliRun r = runCli(ORBIT_BENCH, "--angles 0,180 --seeds 1 --json " + json.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream in(json);
  const nlohmann::json doc = nlohmann::json::parse(in);
  ASSERT_EQ(doc.at("angles").size(), 2u);
  for (const nlohmann::json& a : doc["angles"]) {
    EXPECT_EQ(a.at("ok").get<int>() + a.at("refused").get<int>() + a.at("off").get<int>() +
                  a.at("wrong").get<int>(),
              a.at("pairs").get<int>())
        << a.dump();
  }
  EXPECT_EQ(doc["angles"][0].at("angle_deg").get<double>(), 0.0);
  EXPECT_EQ(doc["angles"][0].at("ok").get<int>(), 1);
  fs::remove(json);
}

TEST(BenchOutputs, CovarianceBenchWritesItsFilesWholeThroughALink) {
  const fs::path dir = pnpba::test::scratchPath("pnpba_bench_outputs");
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path target = dir / "covariance.json", link = dir / "latest.json",
                 plot = dir / "nees.png";
  std::ofstream(target) << "an older run's file\n";
  fs::create_symlink(target.filename(), link);

  // One rendered pair (the rich room, no motion, one seed): about a second.
  const CliRun r = runCli(COVARIANCE_BENCH,
                          "--scenes rich --rotations 0 --translations 0 --conditions clean "
                          "--seeds 1 --json " +
                              link.string() + " --plot " + plot.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::is_symlink(link));
  std::ifstream in(target);
  const nlohmann::json doc = nlohmann::json::parse(in);
  ASSERT_FALSE(doc.at("groups").empty());
  for (const nlohmann::json& g : doc["groups"]) {
    EXPECT_GE(g.at("n").get<int>(), 1) << g.dump();
    EXPECT_TRUE(g.at("nees_mean").is_number()) << g.dump();
  }
  const cv::Mat png = cv::imread(plot.string(), cv::IMREAD_COLOR);
  EXPECT_FALSE(png.empty());
  std::vector<std::string> names;
  for (const fs::directory_entry& e : fs::directory_iterator(dir)) {
    names.push_back(e.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"covariance.json", "latest.json", "nees.png"}));
  fs::remove_all(dir);
}

// The JSON a latency run reports, as docs/benchmarks.md documents it: per set the pairs, the
// percentiles in order, the tallies adding up to the pairs, the stages, and the machine's ORB
// before and after.
TEST(BenchOutputs, LatencyBenchReportsItsSetsAndTheMachine) {
  if (!fs::exists(std::string(PNPBA_SHARED_DATA) + "/slambook_ch7/1.png")) {
    GTEST_SKIP() << "no shared data at " << PNPBA_SHARED_DATA;
  }
  const fs::path json = pnpba::test::scratchPath("pnpba_latency.json");
  const CliRun r = runCli(
      LATENCY_BENCH, "--sets textbook,fr1_desk-odometry --anchors none --json " + json.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream in(json);
  const nlohmann::json doc = nlohmann::json::parse(in);
  ASSERT_EQ(doc.at("sets").size(), 2u);
  // The odometry loop (a set before the textbook pair): its pairs on their own beside it, with
  // their own stages.
  const nlohmann::json& loop = doc["sets"][0];
  EXPECT_EQ(loop.at("name"), "fr1_desk-odometry");
  ASSERT_EQ(loop.at("anchors").size(), 1u);
  const nlohmann::json& own = loop["anchors"][0];
  EXPECT_EQ(own.at("name"), "pnpba-per-pair");
  EXPECT_EQ(own.at("pairs"), loop.at("pairs"));
  EXPECT_GT(own.at("stages_ms").at("features").get<double>(), 0);
  EXPECT_EQ(own.at("stages_ran").at("features"), loop.at("pairs"));
  const nlohmann::json& set = doc["sets"][1];
  EXPECT_EQ(set.at("name"), "textbook");
  EXPECT_EQ(set.at("pairs").get<int>(), 1);
  EXPECT_EQ(set.at("ok").get<int>() + set.at("refused").get<int>(), 1);
  EXPECT_EQ(set.at("wrong").get<int>(), 0);
  EXPECT_GT(set.at("p50_ms").get<double>(), 0);
  EXPECT_LE(set.at("p50_ms").get<double>(), set.at("p95_ms").get<double>());
  EXPECT_LE(set.at("p95_ms").get<double>(), set.at("max_ms").get<double>());
  // Every stage that ran: its median in ms, and the pairs it ran in.
  EXPECT_GT(set.at("stages_ms").at("features").get<double>(), 0);
  EXPECT_LE(set.at("stages_ms").at("features").get<double>(), set.at("max_ms").get<double>());
  EXPECT_EQ(set.at("stages_ran").at("features").get<int>(), 1);
  EXPECT_EQ(set.at("stages_ms").size(), set.at("stages_ran").size());
  EXPECT_GE(doc.at("plugin_load_ms").get<double>(), 0);
  for (const char* when : {"before", "after"}) {
    const nlohmann::json& m = doc.at("machine").at(when);
    EXPECT_GT(m.at("orb_pair_one_thread_ms").get<double>(), 0) << when;
    EXPECT_GT(m.at("orb_pair_two_threads_ms").get<double>(), 0) << when;
  }
  fs::remove(json);
}

// A rendered set's pairs are all rendered before the first is timed (--render-each: each just
// before its estimate): the order changes the times only, never a pair's answer.
TEST(BenchOutputs, LatencyBenchsRenderingOrderChangesNoAnswer) {
  nlohmann::json sets[2];
  const char* orders[2] = {"", " --render-each"};
  for (int k = 0; k < 2; ++k) {
    const fs::path json = pnpba::test::scratchPath("pnpba_latency_order.json");
    const CliRun r = runCli(LATENCY_BENCH, std::string("--sets sweep-poster --anchors none") +
                                               orders[k] + " --json " + json.string());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    std::ifstream in(json);
    const nlohmann::json doc = nlohmann::json::parse(in);
    ASSERT_EQ(doc.at("sets").size(), 1u);
    sets[k] = doc["sets"][0];
    fs::remove(json);
  }
  EXPECT_EQ(sets[0].at("pairs").get<int>(), 36);
  for (const char* count : {"pairs", "ok", "refused", "wrong"}) {
    EXPECT_EQ(sets[0].at(count), sets[1].at(count)) << count;
  }
  EXPECT_EQ(sets[0].at("stages_ran"), sets[1].at("stages_ran"));
}

// wide_baseline_bench renders a batch of pairs before timing any of them (--render-each: each
// just before its methods): every cell's counts are the same either way.
TEST(BenchOutputs, WideBaselineBenchsRenderingOrderChangesNoAnswer) {
  nlohmann::json cells[2];
  const char* orders[2] = {"", " --render-each"};
  for (int k = 0; k < 2; ++k) {
    const fs::path json = pnpba::test::scratchPath("pnpba_wide_baseline_order.json");
    const CliRun r =
        runCli(WIDE_BASELINE_BENCH, std::string("--scenes poster,poor --seeds 1 --rotations 0,45 "
                                                "--translations 0,1 --methods default") +
                                        orders[k] + " --json " + json.string());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    std::ifstream in(json);
    cells[k] = nlohmann::json::parse(in).at("cells");
    fs::remove(json);
  }
  ASSERT_EQ(cells[0].size(), 8u);  // 2 scenes x 2 rotations x 2 translations
  ASSERT_EQ(cells[0].size(), cells[1].size());
  for (size_t i = 0; i < cells[0].size(); ++i) {
    for (const char* field :
         {"scene", "rotation_deg", "translation_m", "method", "pairs", "ok", "refused", "wrong"}) {
      EXPECT_EQ(cells[0][i].at(field), cells[1][i].at(field)) << "cell " << i << " " << field;
    }
  }
}

// --verbose: a pair's line ends with its error against the truth where it was returned, and with
// why where it was refused (the refusal's own message): frames of two scenes are every one
// refused, and every line says why.
TEST(BenchOutputs, LatencyBenchVerboseSaysWhyAPairWasRefused) {
  const std::string shared = PNPBA_SHARED_DATA;
  if (!fs::exists(shared + "/tum_fr1_desk") || !fs::exists(shared + "/tum_fr3_cabinet_keyframes")) {
    GTEST_SKIP() << "no shared data at " << shared;
  }
  const CliRun r = runCli(LATENCY_BENCH, "--sets unrelated --anchors none --verbose");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::istringstream lines(r.out);
  int pairs = 0;
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("unrelated ", 0) != 0 || line.find(" ms ") == std::string::npos) continue;
    ++pairs;
    SCOPED_TRACE(line);
    EXPECT_NE(line.find(" x:"), std::string::npos);  // refused
    const std::string why = line.substr(line.rfind(" | ") + 3);
    EXPECT_NE(why, "-");
    EXPECT_NE(why.find("depth path: "), std::string::npos);  // the last word was the depth path's
  }
  EXPECT_GT(pairs, 0);
}

// A user's own sequence (--sequence): its pairs (i, i+k) at the chosen gaps and spacing, its
// camera by evaluate_tum's rule, and each pair scored as evaluate_tum scores the same pair
// (within 2 deg / 5 cm is ok; more than 10 deg or 50 cm off is wrong).
TEST(BenchOutputs, LatencyBenchTimesAUsersSequenceAsEvaluateTumScoresIt) {
  const std::string folder = std::string(PNPBA_SHARED_DATA) + "/tum_fr3_cabinet_keyframes";
  if (!fs::exists(folder + "/poses.txt")) GTEST_SKIP() << "no shared data at " << folder;
  const std::string stem = (pnpba::test::scratchPath("pnpba_sequence")).string();
  const CliRun r =
      runCli(LATENCY_BENCH, "--sequence " + folder + " --gaps 3 --every 9 --anchors none --json " +
                                stem + "_latency.json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const CliRun e =
      runCli(EVALUATE_TUM, folder + " --gaps 3 --methods rgbd --json " + stem + "_evaluation.json");
  ASSERT_EQ(e.exit_code, 0) << e.err;
  std::ifstream latency_in(stem + "_latency.json"), evaluation_in(stem + "_evaluation.json");
  const nlohmann::json latency = nlohmann::json::parse(latency_in);
  const nlohmann::json evaluation = nlohmann::json::parse(evaluation_in);

  // Only the sequence ran (no --sets), named by its folder, through freiburg3's camera.
  ASSERT_EQ(latency.at("sets").size(), 1u);
  const nlohmann::json& set = latency["sets"][0];
  EXPECT_EQ(set.at("name"), "tum_fr3_cabinet_keyframes");
  EXPECT_EQ(set.at("folder"), folder);
  EXPECT_NE(set.at("camera").get<std::string>().find("freiburg3"), std::string::npos);
  // The 29 key frames at i = 0, 9, 18, 27: (0, 3), (9, 12), (18, 21); 30 is past the end.
  int ok = 0, refused = 0, wrong = 0, scored = 0;
  for (const nlohmann::json& p : evaluation.at("pairs")) {
    if (p.at("i").get<int>() % 9 != 0) continue;
    ++scored;
    const nlohmann::json& m = p.at("rgbd");
    if (!m.at("ok").get<bool>()) {
      ++refused;
      continue;
    }
    const double deg = m.at("rot_deg").get<double>(), cm = m.at("trans_cm").get<double>();
    if (deg <= 2.0 && cm <= 5.0) ++ok;
    if (deg > 10.0 || cm > 50.0) ++wrong;
  }
  EXPECT_EQ(scored, 3);
  EXPECT_EQ(set.at("pairs").get<int>(), 3);
  EXPECT_EQ(set.at("ok").get<int>(), ok);
  EXPECT_EQ(set.at("refused").get<int>(), refused);
  EXPECT_EQ(set.at("wrong").get<int>(), wrong);
  EXPECT_LE(set.at("p50_ms").get<double>(), set.at("p95_ms").get<double>());
  EXPECT_LE(set.at("p95_ms").get<double>(), set.at("max_ms").get<double>());
  fs::remove(stem + "_latency.json");
  fs::remove(stem + "_evaluation.json");
}

// A folder that is not one, or that gives no pair at the chosen gaps, is one line naming it
// before any pair is timed (the second folder checked before the first one's pairs run).
TEST(BenchOutputs, LatencyBenchNamesASequenceWithoutPairsBeforeTiming) {
  const std::string folder = std::string(PNPBA_SHARED_DATA) + "/tum_fr3_cabinet_keyframes";
  if (!fs::exists(folder + "/poses.txt")) GTEST_SKIP() << "no shared data at " << folder;
  const CliRun missing = runCli(LATENCY_BENCH, "--sequence " + folder +
                                                   " --sequence /nonexistent-pnpba-sequence "
                                                   "--anchors none");
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_EQ(missing.err, "latency_bench: /nonexistent-pnpba-sequence: not a folder\n");
  EXPECT_EQ(missing.out, "");
  const CliRun none = runCli(LATENCY_BENCH, "--sequence " + folder + " --gaps 40 --anchors none");
  EXPECT_EQ(none.exit_code, 2);
  EXPECT_EQ(none.err, "latency_bench: " + folder +
                          ": no pair (i, i+k) for k in 40 with both frames' ground truth (29 "
                          "frames, 0 without ground truth)\n");
  EXPECT_EQ(none.out, "");
}

}  // namespace
