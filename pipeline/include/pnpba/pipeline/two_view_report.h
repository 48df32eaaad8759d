// The machine-readable report of a two-view estimate (pose_estimation_3d2d --json, and what the
// Python module returns). A failed estimate's report says "ok": false and why, and holds no
// pose: no T, R_init, t_init or covariance.
#pragma once

#include <string>

#include "pnpba/pipeline/two_view.h"

namespace pnpba {

std::string twoViewReportJson(const TwoViewResult& result, const std::string& ba_mode);

// One line of where the time went, the stages that ran in the order they run, e.g.
// "time (ms): features 3.9, matching 2.1, depth 0.3, pnp 0.8, ba 2.3; total 10.1"
// (pose_estimation_3d2d --verbose). The SIFT retry is timed whole, its own stages included.
std::string stageTimesLine(const StageTimes& times);

}  // namespace pnpba
