// evaluate_tum's per-pair times are the pairs' own: Open3D's plugin opens before the first pair
// when a method's depth path may take one of Open3D's steps, and not at all when none does, which
// is every method's default (the depth registration is pnpba's own).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "pnpba/evaluation/tum_evaluation.h"
#include "shared_data.h"

namespace pnpba {
namespace {

TEST(TumEvaluationTiming, OpensNoPluginForMethodsWhoseDepthPathTakesNoneOfOpen3dsSteps) {
  PNPBA_REQUIRE_SHARED_DATA();
  TumEvaluationOptions o;
  o.folder = test::sharedData("tum_fr1_desk");
  o.gaps = {8};                        // one pair
  o.methods = {"opencv", "textbook"};  // neither has a depth path
  const TumEvaluation baselines = evaluateTumSequence(o);
  EXPECT_EQ(baselines.plugin_load_ms, -1);

  o.methods = {"opencv", "rgbd"};  // a depth path, pnpba's own registration
  std::vector<std::string> lines;
  const TumEvaluation ev =
      evaluateTumSequence(o, [&lines](const std::string& line) { lines.push_back(line); });
  EXPECT_EQ(ev.plugin_load_ms, -1);
  EXPECT_EQ(lines.size(), 1u);  // progress stays one line per pair
  const nlohmann::json j = nlohmann::json::parse(evaluationJson(ev));
  EXPECT_EQ(j.at("plugin_load_ms").get<double>(), -1);
}

}  // namespace
}  // namespace pnpba
