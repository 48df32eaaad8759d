// "Bundle Adjustment in the Large" problems: the text format (DESIGN.md section 4), its
// validation, PLY export, Ceres-bundle_adjuster-style normalisation and perturbation, and the
// SparseOptimizer graph of a problem (cameras: VertexBalCamera, points: VertexPointXYZ,
// marginalised; one EdgeBalProjection per observation).
#pragma once

#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

#include "pnpba/bal/bal_observation.h"
#include "pnpba/bal/bal_types.h"
#include "pnpba/optimize/sparse_optimizer.h"

namespace pnpba {

struct BalProblem {
  int num_cameras = 0, num_points = 0;
  std::vector<BalObservation> observations;
  std::vector<double> cameras;  // 9 per camera: r, t, f, k1, k2
  std::vector<double> points;   // 3 per point

  // Cost 1/2 sum |observed - predicted|^2 and RMS reprojection error (px per observation).
  double cost() const;
  double rmsPixels() const;
};

// Reads and validates everything: header counts, each observation's indices in range, every
// camera and point observed, numbers finite, file not truncated, nothing after the last value.
// Throws Error "<path>:<line>: <problem>" at the first problem.
BalProblem readBal(const std::string& path);
void writeBal(std::ostream& out, const BalProblem& problem);
// Camera centres -R^T t in green, points in white; binary little-endian or ASCII.
void writeBalPly(std::ostream& out, const BalProblem& problem, bool binary);

// Ceres bundle_adjuster's normalisation: points centred on their per-axis median and scaled so
// the median absolute deviation is 100; cameras moved with them. Projections do not change.
void normalizeBal(BalProblem& problem);

struct BalPerturbation {
  double rotation_sigma = 0;     // radians, added to each angle-axis component
  double translation_sigma = 0;  // added to each camera centre coordinate
  double point_sigma = 0;        // added to each point coordinate
  uint64_t seed = 38401;
};
void perturbBal(BalProblem& problem, const BalPerturbation& perturbation);

// Adds the problem's graph to an empty optimizer (camera i: vertex id i, point j: vertex id
// num_cameras + j). `kernel`: "none", "huber" or "cauchy" (width 1 px).
void buildBalGraph(SparseOptimizer& optimizer, const BalProblem& problem,
                   const std::string& kernel = "none");
// Copies the optimizer's estimates back into the problem.
void readBalGraph(const SparseOptimizer& optimizer, BalProblem& problem);

}  // namespace pnpba
