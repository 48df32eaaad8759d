// Generated BAL problems with known ground truth, to measure the solvers beyond the public files:
// cameras on a ring around a scene (a closed trajectory, each looking at the centre, the BAL
// camera model with realistic f, k1, k2), points in the scene each seen by K cameras that are
// neighbours on the ring (tracks, as a sequence makes them), pixel noise on the observations,
// and a perturbed start.
#pragma once

#include <cstdint>
#include <string>

#include "pnpba/bal/bal_problem.h"

namespace pnpba {

struct BalSyntheticOptions {
  int cameras = 50;
  int points = 5000;
  int observations_per_point = 4;               // track length K (>= 2, <= cameras)
  double noise_px = 0.5;                        // Gaussian pixel noise on every observation
  BalPerturbation start{0.002, 0.05, 0.05, 1};  // rad, m, m; seed
  uint64_t seed = 1;
  std::string validate() const;  // empty when valid
};

struct BalSyntheticProblem {
  BalProblem truth;  // true cameras and points, with the noisy observations
  BalProblem start;  // the same observations, perturbed cameras and points
};

// Throws Error for invalid options.
BalSyntheticProblem generateBalProblem(const BalSyntheticOptions& options);

}  // namespace pnpba
