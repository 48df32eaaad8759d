// The machine-readable report of a two-view estimate (pose_estimation_3d2d --json, and what the
// Python module returns). A failed estimate's report says "ok": false and why, and holds no
// pose: no T, R_init, t_init or covariance.
#pragma once

#include <string>

#include "pnpba/pipeline/two_view.h"

namespace pnpba {

std::string twoViewReportJson(const TwoViewResult& result, const std::string& ba_mode);

}  // namespace pnpba
