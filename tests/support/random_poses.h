// Reproducible random poses and points for tests (fixed seeds).
#pragma once

#include <random>

#include "pnpba/optimize/se3_quat.h"

namespace pnpba::test {

class RandomScene {
 public:
  explicit RandomScene(unsigned seed) : rng_(seed) {}

  double uniform(double lo, double hi) { return std::uniform_real_distribution<>(lo, hi)(rng_); }
  double normal(double sigma) { return std::normal_distribution<>(0.0, sigma)(rng_); }

  Eigen::Vector3d unitVector() {
    Eigen::Vector3d v(normal(1), normal(1), normal(1));
    return v.normalized();
  }
  // Rotation of angle up to max_angle (radians) about a random axis, translation up to max_t.
  SE3Quat pose(double max_angle, double max_t) {
    const Eigen::AngleAxisd aa(uniform(0, max_angle), unitVector());
    return SE3Quat(aa.toRotationMatrix(), max_t * uniform(0, 1) * unitVector());
  }
  // A world point that lies in front of camera T at a depth in [z_min, z_max], within a
  // +-35 degree cone.
  Eigen::Vector3d pointInFront(const SE3Quat& T, double z_min, double z_max) {
    const double z = uniform(z_min, z_max);
    const Eigen::Vector3d P(uniform(-0.7, 0.7) * z, uniform(-0.7, 0.7) * z, z);
    return T.inverse().map(P);
  }

 private:
  std::mt19937 rng_;
};

}  // namespace pnpba::test
