// A rendered photometric scene with exact ground truth, for direct-BA tests and benchmarks:
// three planes with a smooth multi-scale texture (sinusoids of 0.45-0.9 m wavelength, so the
// photometric error is smooth over several pixels) seen by cameras with the exercise's
// intrinsics.
#pragma once

#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "pnpba/direct/direct_ba.h"

namespace pnpba::test {

// A smooth textured world: three planes whose intensity is a sum of long-wavelength sinusoids,
// so the photometric error is smooth over several pixels.
inline double texture(double s, double t) {
  return 128 + 40 * std::sin(2 * M_PI * s / 0.9) * std::cos(2 * M_PI * t / 0.7) +
         30 * std::sin(2 * M_PI * (s + t) / 0.45) + 20 * std::cos(2 * M_PI * (s - 2 * t) / 0.55);
}

// Intensity seen along a world ray: back wall z = 4, floor y = 1.2, left wall x = -2.
inline double worldIntensity(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                             double* depth_t) {
  double best = 1e9, value = 0;
  auto hit = [&](double t, double s_coord, double t_coord) {
    if (t > 1e-6 && t < best) best = t, value = texture(s_coord, t_coord);
  };
  if (std::abs(dir.z()) > 1e-12) {
    const double t = (4.0 - origin.z()) / dir.z();
    const Eigen::Vector3d p = origin + t * dir;
    hit(t, p.x(), p.y());
  }
  if (std::abs(dir.y()) > 1e-12) {
    const double t = (1.2 - origin.y()) / dir.y();
    const Eigen::Vector3d p = origin + t * dir;
    if (p.z() < 4.0) hit(t, p.x() + 7, p.z());
  }
  if (std::abs(dir.x()) > 1e-12) {
    const double t = (-2.0 - origin.x()) / dir.x();
    const Eigen::Vector3d p = origin + t * dir;
    if (p.z() < 4.0 && p.y() < 1.2) hit(t, p.z() + 3, p.y());
  }
  if (depth_t) *depth_t = best;
  return value;
}

constexpr double kFx = 277.34, kFy = 291.402, kCx = 312.234, kCy = 239.777;

inline std::shared_ptr<GrayImage> render(const SE3Quat& T_cw, int w = 640, int h = 480) {
  auto image = std::make_shared<GrayImage>();
  image->width = w, image->height = h;
  image->pixels.resize(static_cast<size_t>(w) * h);
  const SE3Quat T_wc = T_cw.inverse();
  const Eigen::Matrix3d R = T_wc.rotation().toRotationMatrix();
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const Eigen::Vector3d ray((u - kCx) / kFx, (v - kCy) / kFy, 1.0);
      image->pixels[static_cast<size_t>(v) * w + u] =
          static_cast<float>(worldIntensity(T_wc.translation(), R * ray, nullptr));
    }
  return image;
}

struct RenderedDirectProblem {
  DirectBaProblem problem;  // poses 1-3 perturbed by 1.1 deg / 3.5 cm, points by 2 cm
  std::vector<SE3Quat> truth;
};

// Four cameras; patches sampled in image 0 on a 16-pixel grid.
inline RenderedDirectProblem renderedDirectProblem() {
  RenderedDirectProblem r;
  std::vector<SE3Quat>& truth = r.truth;
  DirectBaProblem& problem = r.problem;
  // Four cameras, patches sampled in image 0 on a grid, poses 1-3 and points perturbed.
  truth = {SE3Quat()};
  for (int k = 1; k < 4; ++k) {
    const Eigen::AngleAxisd r(0.03 * k, Eigen::Vector3d(0.2, 1, 0.1).normalized());
    truth.push_back(SE3Quat(r.toRotationMatrix(), Eigen::Vector3d(-0.08 * k, 0.02 * k, 0.03)));
  }
  problem.fx = kFx, problem.fy = kFy, problem.cx = kCx, problem.cy = kCy;
  for (const SE3Quat& T : truth) problem.images.push_back(render(T));
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0, 0.02);
  for (int v = 40; v < 440; v += 16) {
    for (int u = 40; u < 600; u += 16) {
      double depth = 0;
      const Eigen::Vector3d ray((u - kCx) / kFx, (v - kCy) / kFy, 1.0);
      worldIntensity(Eigen::Vector3d::Zero(), ray, &depth);
      DirectPoint p;
      for (int dx = -2; dx <= 1; ++dx)
        for (int dy = -2; dy <= 1; ++dy)
          p.patch[4 * (dx + 2) + (dy + 2)] = problem.images[0]->sample(u + dx, v + dy);
      p.Pw = depth * ray + Eigen::Vector3d(noise(rng), noise(rng), noise(rng));  // >= 2 cm off
      problem.points.push_back(p);
    }
  }
  for (size_t k = 0; k < truth.size(); ++k) {
    Vector6d d = Vector6d::Zero();
    if (k > 0) d << 0.0175, -0.008, 0.006, 0.03, -0.015, 0.01;  // 1.1 deg, 3.5 cm
    problem.poses.push_back({std::to_string(k), SE3Quat::exp(d) * truth[k]});
  }
  return r;
}

}  // namespace pnpba::test
