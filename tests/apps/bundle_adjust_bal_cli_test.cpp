// bundle_adjust_bal as a user runs it: a solve with every output, and malformed input with its
// one-line message, exit 2 and no output file left behind.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "cli_runner.h"
#include "scratch_dir.h"
#include "shared_data.h"

namespace {

namespace fs = std::filesystem;
using pnpba::test::CliRun;

CliRun run(const std::string& args) { return pnpba::test::runCli(BUNDLE_ADJUST_BAL, args); }

std::string temp(const std::string& name) {
  return (pnpba::test::scratchDir() / ("pnpba_balcli_" + name)).string();
}

TEST(BundleAdjustBalCli, SolvesAndWritesEveryOutput) {
  PNPBA_REQUIRE_SHARED_DATA();
  const std::string out = temp("out.txt"), ply = temp("final.ply"), json = temp("r.json");
  for (const auto& f : {out, ply, json}) fs::remove(f);
  const CliRun r =
      run(pnpba::test::sharedData("bal/dubrovnik-3-7-pre.txt") + " --iterations 20 --output " +
          out + " --final-ply " + ply + " --json " + json);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("iter"), std::string::npos);
  const auto j = nlohmann::json::parse(pnpba::test::slurp(json));
  for (const char* key : {"initial_cost", "final_cost", "rms_px_initial", "rms_px_final",
                          "iterations", "termination", "time_s"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  EXPECT_LT(j["final_cost"].get<double>(), j["initial_cost"].get<double>());
  // The written problem reads back with the solved cost: run again on it, no iterations needed.
  const CliRun again = run(out + " --iterations 1 --json " + json);
  ASSERT_EQ(again.exit_code, 0) << again.err;
  const auto j2 = nlohmann::json::parse(pnpba::test::slurp(json));
  EXPECT_NEAR(j2["initial_cost"].get<double>(), j["final_cost"].get<double>(),
              1e-9 + 1e-6 * j["final_cost"].get<double>());
  EXPECT_EQ(pnpba::test::slurp(ply).rfind("ply\nformat binary_little_endian", 0), 0u);
}

TEST(BundleAdjustBalCli, MalformedInputIsExit2AndLeavesNoOutput) {
  const std::string bad = temp("bad.txt"), out = temp("never.txt");
  std::ofstream(bad) << "1 1 1\n0 5 1.5 2.5\n0 0 0 0 0 0 500 0 0\n0 0 -1\n";
  fs::remove(out);
  const CliRun r = run(bad + " --output " + out);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err, "bundle_adjust_bal: " + bad + ":2: point index 5 out of range (1 points)\n");
  EXPECT_FALSE(fs::exists(out));
  EXPECT_FALSE(fs::exists(out + ".tmp-pnpba"));
}

}  // namespace

namespace {

TEST(BundleAdjustBalCli, JsonToStandardOutputIsParseableAndTheTableGoesToStderr) {
  PNPBA_REQUIRE_SHARED_DATA();
  const CliRun r =
      run(pnpba::test::sharedData("bal/dubrovnik-3-7-pre.txt") + " --iterations 5 --json -");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);  // throws if anything else is on stdout
  EXPECT_LT(j["final_cost"].get<double>(), j["initial_cost"].get<double>());
  EXPECT_NE(r.err.find("iter"), std::string::npos);
}

}  // namespace

namespace {

TEST(BalSyntheticCli, GeneratedProblemSolvesBelowTheTruthsCost) {
  const std::string problem = temp("gen.txt"), truth = temp("gen_truth.txt"),
                    json = temp("gen.json");
  const CliRun g = pnpba::test::runCli(BAL_SYNTHETIC,
                                       "--cameras 8 --points 300 --noise-px 0.5 "
                                       "--seed 3 --output " +
                                           problem + " --ground-truth " + truth);
  ASSERT_EQ(g.exit_code, 0) << g.err;
  // Both files are valid BAL problems with the same observations; solving the perturbed one
  // reaches a least-squares minimum, at or below the cost of the true parameters.
  const CliRun t = run(truth + " --iterations 1 --json " + json);
  ASSERT_EQ(t.exit_code, 0) << t.err;
  const double truth_cost = nlohmann::json::parse(pnpba::test::slurp(json))["initial_cost"];
  const CliRun s = run(problem + " --json " + json);
  ASSERT_EQ(s.exit_code, 0) << s.err;
  const auto j = nlohmann::json::parse(pnpba::test::slurp(json));
  EXPECT_GT(j["initial_cost"].get<double>(), 10 * truth_cost);
  EXPECT_LE(j["final_cost"].get<double>(), truth_cost * (1 + 1e-9));
  EXPECT_EQ(j["solver"], "pnpba");
  EXPECT_EQ(j["linear_solver"], "dense");
  EXPECT_GT(j["peak_memory_mb"].get<double>(), 0);
}

TEST(BalSyntheticCli, BadOptionsAreExit2WithOneLine) {
  const CliRun r = pnpba::test::runCli(BAL_SYNTHETIC, "--cameras 1 --output " + temp("x.txt"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err, "bal_synthetic: cameras must be >= 2\n");
  EXPECT_FALSE(fs::exists(temp("x.txt")));
}

}  // namespace
