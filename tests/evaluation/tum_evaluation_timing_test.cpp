// evaluate_tum's per-pair times are the pairs' own: the depth path's plugin opens before the
// first pair when a method may need it, and not at all when none does.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "pnpba/evaluation/tum_evaluation.h"
#include "pnpba/pipeline/depth_registration.h"
#include "shared_data.h"

namespace pnpba {
namespace {

TEST(TumEvaluationTiming, OpensTheDepthPathsPluginBeforeThePairsWhereAMethodMayNeedIt) {
  PNPBA_REQUIRE_SHARED_DATA();
  TumEvaluationOptions o;
  o.folder = test::sharedData("tum_fr1_desk");
  o.gaps = {8};                        // one pair
  o.methods = {"opencv", "textbook"};  // neither has a depth path
  const TumEvaluation baselines = evaluateTumSequence(o);
  EXPECT_EQ(baselines.plugin_load_ms, -1);

  o.methods = {"opencv", "rgbd"};
  std::vector<std::string> lines;
  const TumEvaluation ev =
      evaluateTumSequence(o, [&lines](const std::string& line) { lines.push_back(line); });
  EXPECT_GE(ev.plugin_load_ms, 0);
  EXPECT_EQ(lines.size(), 1u);  // progress stays one line per pair
  // Opened for good: a second open has nothing to do.
  EXPECT_EQ(preloadDepthRegistration(), 0);
  const nlohmann::json j = nlohmann::json::parse(evaluationJson(ev));
  EXPECT_EQ(j.at("plugin_load_ms").get<double>(), ev.plugin_load_ms);
}

}  // namespace
}  // namespace pnpba
