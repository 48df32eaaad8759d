// Private to the depth-only registration (registration.cpp): the FPFH pair feature of two oriented
// points, binned as Open3D bins it (fpfh.cpp), one pair at a time or four at once with AVX2. The
// four-wide kernel does every pair's arithmetic in the scalar one's order without fused
// multiply-adds, so its bins are the scalar bins to the last case
// (tests/pipeline/pair_bins_test.cpp); the few pairs it cannot settle (a bin edge within 1e-6, a
// zero-length line or cross product) it leaves to the scalar function. The pair features were over
// half of the descriptors' time.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "angle_bin.h"

namespace pnpba {

inline int clampedBin(double bin) {
  const int b = static_cast<int>(std::floor(bin));
  return b >= 11 ? 10 : std::max(0, b);
}

// The three bins of the pair (p1, n1) -> (p2, n2): Darboux frame on the point whose normal is
// nearer perpendicular to the line between them, then (theta, alpha, phi) as Open3D bins them.
// The pair (p2, n2) -> (p1, n1) puts the frame on the same point and gives the same bins to the
// last bit (d negated twice, dot products negated), unless the two normals make the same angle
// with the line (then both directions put it on their first point): `reversible` says which.
struct PairBins {
  int theta = 0, alpha = 0, phi = 0;
  bool reversible = true;
};

inline PairBins pairBins(const Eigen::Vector3d& p1, const Eigen::Vector3d& n1,
                         const Eigen::Vector3d& p2, const Eigen::Vector3d& n2) {
  double alpha = 0, phi = 0;
  int theta_bin = 5;  // an angle of 0
  bool reversible = true;
  Eigen::Vector3d d = p2 - p1;
  const double length = d.norm();
  if (length != 0) {
    const double cos1 = n1.dot(d) / length, cos2 = n2.dot(d) / length;
    // acos(|cos1|) > acos(|cos2|) exactly when |cos1| < |cos2|: acos is decreasing.
    const bool swap = std::abs(cos1) < std::abs(cos2);
    reversible = std::abs(cos1) != std::abs(cos2);
    const Eigen::Vector3d& u = swap ? n2 : n1;
    const Eigen::Vector3d& other = swap ? n1 : n2;
    if (swap) d = -d;
    Eigen::Vector3d v = d.cross(u);
    const double v_norm = v.norm();
    if (v_norm != 0) {
      v /= v_norm;
      const Eigen::Vector3d w = u.cross(v);
      phi = swap ? -cos2 : cos1;
      alpha = v.dot(other);
      theta_bin = fastAngleBin(w.dot(other), u.dot(other));
    }
  }
  return {theta_bin, 11 + clampedBin(11 * (alpha + 1.0) * 0.5),
          22 + clampedBin(11 * (phi + 1.0) * 0.5), reversible};
}

// Where cpuHasAvx2Fma() (pnpba/core/cpu_features.h): the bins of the pairs (p1, n1) -> (p2[k],
// n2[k]) for k < 4 (each a pointer to 3 doubles) into out[k]; returns a mask of the k it left to
// pairBins (bit k set: out[k] not written).
int pairBinsAvx2(const double* p1, const double* n1, const double* const p2[4],
                 const double* const n2[4], PairBins out[4]);

}  // namespace pnpba
