// Initial pose T_21 from 3D-2D correspondences: EPnP (epnp.h) inside RANSAC, then EPnP refit on the
// inliers (kEpnpRansac), or the textbook's cv::solvePnP(SOLVEPNP_ITERATIVE) on all pairs
// (kIterative, for --preset textbook). Pixels must be undistorted.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "pnpba/features/correspondences.h"
#include "pnpba/optimize/se3_quat.h"

namespace pnpba {

enum class PnpMethod { kEpnpRansac, kIterative };

struct RansacOptions {
  double threshold_px = 3.0;  // inlier if the reprojection error is below this
  double confidence = 0.999;  // stop when an all-inlier sample was drawn with this probability
  int max_iterations = 500;
  uint64_t seed = 42;   // fixed: the same input gives the same pose
  int min_inliers = 6;  // fewer -> failure
  // Above 1, the samples of a long search are solved on TBB's workers, in chunks whichever core
  // is free takes; 1: on the calling thread alone. The result is the same either way.
  int num_threads = 2;
  std::string validate() const;
};

struct PnpResult {
  bool ok = false;
  std::string failure;  // why, when !ok: "5 inliers < 6 required"
  SE3Quat T_21;
  std::vector<char> inlier;  // per correspondence
  int num_inliers = 0;
  int iterations = 0;  // RANSAC samples drawn
  // Ambiguity evidence: among the strongest RANSAC poses that differ from one another (by
  // more than 5 degrees or max(5 cm, 20 % of |t|)), the most pairs one of them explains that
  // T_21 does not. Two poses sharing their inliers are one explanation of the data; a rival
  // supported by other pairs (repeated texture, a second rigid motion) means the data do not
  // decide between them.
  int competitor_inliers = 0;
};

// True when two poses differ as much as competitor_inliers requires.
bool posesDiffer(const SE3Quat& a, const SE3Quat& b);

PnpResult estimatePnp(const Correspondences& pairs, const PinholeCamera& camera, PnpMethod method,
                      const RansacOptions& options);

// Squared reprojection error of each pair under T_21 (infinity behind the camera).
std::vector<double> reprojectionErrors2(const Correspondences& pairs, const SE3Quat& T_21,
                                        const PinholeCamera& camera);

}  // namespace pnpba
