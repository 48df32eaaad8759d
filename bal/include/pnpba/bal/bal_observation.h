// One observation of a BAL problem: which camera saw which point, and where (pixels, BAL's
// centred convention). On its own so that code built apart from Eigen can read observations.
#pragma once

namespace pnpba {

struct BalObservation {
  int camera = 0, point = 0;
  double u = 0, v = 0;
};

}  // namespace pnpba
