// direct_ba as a user runs it: bad input with file, line, one-line message and exit 2; a short
// solve writing poses in the input's format and the JSON summary.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli_runner.h"
#include "scratch_dir.h"
#include "shared_data.h"

namespace {

namespace fs = std::filesystem;
using pnpba::test::CliRun;

CliRun run(const std::string& args) { return pnpba::test::runCli(DIRECT_BA, args); }

std::string temp(const std::string& name, const std::string& text) {
  const std::string path = (pnpba::test::scratchDir() / ("pnpba_dba_" + name)).string();
  std::ofstream(path) << text;
  return path;
}

class DirectBaCli : public ::testing::Test {
 protected:
  void SetUp() override {
    PNPBA_REQUIRE_SHARED_DATA();
    dir_ = pnpba::test::sharedData("direct_ba");
  }
  std::string dir_;
};

TEST_F(DirectBaCli, PoseLineWithWrongColumnCount) {
  const std::string poses = temp("poses.txt", "1 0 0 0 0 0 0 1\n1 0 0 0 0 0 1\n");
  const CliRun r = run("--poses " + poses + " --points " + dir_ + "/points.txt --images " + dir_);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err, "direct_ba: " + poses +
                       ":2: expected 8 numbers (timestamp tx ty tz qx qy qz qw), got 7\n");
}

TEST_F(DirectBaCli, ShortPointLineAndNonFiniteValues) {
  const std::string points = temp("points.txt", "1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18\n");
  CliRun r = run("--poses " + dir_ + "/poses.txt --points " + points + " --images " + dir_);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err, "direct_ba: " + points +
                       ":1: expected 19 numbers (x y z and 16 intensities), got 18\n");
  const std::string nan = temp("nan.txt", "1 0 0 nan 0 0 0 1\n");
  r = run("--poses " + nan + " --points " + dir_ + "/points.txt --images " + dir_);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err, "direct_ba: " + nan + ":1: non-finite value 'nan'\n");
}

TEST_F(DirectBaCli, MissingImage) {
  const CliRun r = run("--poses " + dir_ + "/poses.txt --points " + dir_ +
                       "/points.txt --images /nonexistent-images");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err, "direct_ba: /nonexistent-images/0.png: cannot open file\n");
}

TEST_F(DirectBaCli, ShortSolveWritesPosesAndJson) {
  const std::string out = temp("out_poses.txt", ""), json = temp("r.json", "");
  const CliRun r =
      run("--poses " + dir_ + "/poses.txt --points " + dir_ + "/points.txt --images " + dir_ +
          " --huber 1 --iterations 2 --output-poses " + out + " --json " + json);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(pnpba::test::slurp(json));
  for (const char* key : {"initial_cost", "final_cost", "active_edges_initial",
                          "active_edges_final", "iterations", "time_s", "pose_change"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  EXPECT_EQ(j["active_edges_initial"], 24522);
  EXPECT_EQ(j["pose_change"].size(), 7u);
  // The written poses read back as a valid input of the same shape.
  const CliRun again = run("--poses " + out + " --points " + dir_ + "/points.txt --images " + dir_ +
                           " --iterations 1");
  EXPECT_EQ(again.exit_code, 0) << again.err;
}

TEST_F(DirectBaCli, PosesToStandardOutputAreTheOnlyThingThere) {
  const CliRun r = run("--poses " + dir_ + "/poses.txt --points " + dir_ + "/points.txt --images " +
                       dir_ + " --huber 1 --iterations 1 --output-poses /dev/stdout");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // Seven TUM pose lines of 8 numbers each, nothing else; the summary went to stderr.
  std::istringstream lines(r.out);
  int count = 0;
  for (std::string line; std::getline(lines, line); ++count) {
    std::istringstream fields(line);
    double v = 0;
    int n = 0;
    while (fields >> v) ++n;
    EXPECT_EQ(n, 8) << line;
  }
  EXPECT_EQ(count, 7);
  EXPECT_NE(r.err.find("cost"), std::string::npos);
}

}  // namespace
