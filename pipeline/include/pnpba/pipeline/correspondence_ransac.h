// Rigid poses from putative 3D-3D correspondences (descriptor matches between two point clouds):
// a RANSAC over triples that keeps EVERY distinct pose with support, best first, not just one.
//
// A texture-poor scene (a cabinet, a wall and a floor) has several poses that explain the
// depths almost equally well: a slide along a wall, a flip of a box. A search that returns one
// answer hides that; returning each well-supported rival lets the depth path's evidence
// (colour, feature pairs, both depth images) choose between them, or refuse when it cannot.
//
// Each hypothesis is scored on the correspondences themselves (how many land within
// inlier_distance_m), not on the clouds, so a hypothesis costs O(correspondences) and the search
// runs in milliseconds where scoring against a k-d tree of the cloud cost seconds. Triples whose
// edge lengths differ between the clouds are dropped before any pose is computed.
//
// Deterministic: iterations run in fixed blocks, each with its own seeded generator, and the
// blocks' results are merged in block order, so the same input gives the same poses on every run
// and for any number of threads. T_21 maps source (camera-1) points onto target (camera-2) points.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "pnpba/optimize/se3_quat.h"

namespace pnpba {

struct CorrespondenceRansacOptions {
  double inlier_distance_m = 0.15;  // a correspondence supports a pose when it lands this close
  double edge_similarity = 0.9;     // a triple's edge lengths agree to this ratio in both clouds
  int max_iterations = 100000;      // triples drawn at most
  // Stop once the best pose's triple would have been drawn with this probability.
  double confidence = 0.9999;
  int max_candidates = 3;      // distinct poses returned at most
  double rival_support = 0.5;  // a distinct pose is returned with this share of the best's support
  double distinct_deg = 5.0;   // poses differing by more than this rotation ...
  double distinct_m = 0.25;    // ... or this translation are distinct
  unsigned seed = 42;
  int threads = 2;
  std::string validate() const;  // empty when valid
};

struct RigidCandidate {
  SE3Quat T_21;
  int support = 0;  // correspondences within inlier_distance_m
};

struct CorrespondenceRansacStats {
  int iterations = 0;  // triples drawn
  int hypotheses = 0;  // triples that passed the edge check and were scored
};

// source[i] and target[i] are one putative correspondence. Returns the distinct poses whose
// support is at least rival_support of the best's (and at least 3), best first, each refined by
// least squares on its inliers; empty when fewer than 3 correspondences or no triple agrees.
// Throws Error for invalid options or sizes that differ.
std::vector<RigidCandidate> ransacRigidPoses(const std::vector<Eigen::Vector3d>& source,
                                             const std::vector<Eigen::Vector3d>& target,
                                             const CorrespondenceRansacOptions& options,
                                             CorrespondenceRansacStats* stats = nullptr);

}  // namespace pnpba
