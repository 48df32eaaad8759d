#include "pnpba/synthetic/synthetic_scene.h"

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

namespace pnpba {

namespace {

constexpr int kTextureSize = 1024;

// Random rectangles, discs and lines on a noisy base: many corners at several scales.
cv::Mat makeTexture(std::mt19937& rng) {
  std::uniform_int_distribution<int> pos(0, kTextureSize - 1), size(6, 90), shade(0, 255);
  cv::Mat t(kTextureSize, kTextureSize, CV_8UC3,
            cv::Scalar(shade(rng) / 2 + 64, shade(rng) / 2 + 64, shade(rng) / 2 + 64));
  for (int i = 0; i < 900; ++i) {
    const cv::Scalar c(shade(rng), shade(rng), shade(rng));
    const cv::Point p(pos(rng), pos(rng));
    switch (i % 3) {
      case 0:
        cv::rectangle(t, cv::Rect(p.x, p.y, size(rng), size(rng)), c, cv::FILLED);
        break;
      case 1:
        cv::circle(t, p, size(rng) / 2, c, cv::FILLED, cv::LINE_AA);
        break;
      default:
        cv::line(t, p, cv::Point(pos(rng), pos(rng)), c, 2 + size(rng) / 30, cv::LINE_AA);
    }
  }
  return t;
}

cv::Vec3b sampleBilinear(const cv::Mat& t, double x, double y) {
  x = std::clamp(x, 0.0, t.cols - 1.001);
  y = std::clamp(y, 0.0, t.rows - 1.001);
  const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
  const double ax = x - x0, ay = y - y0;
  cv::Vec3b out;
  for (int c = 0; c < 3; ++c) {
    const double v = (1 - ax) * (1 - ay) * t.at<cv::Vec3b>(y0, x0)[c] +
                     ax * (1 - ay) * t.at<cv::Vec3b>(y0, x0 + 1)[c] +
                     (1 - ax) * ay * t.at<cv::Vec3b>(y0 + 1, x0)[c] +
                     ax * ay * t.at<cv::Vec3b>(y0 + 1, x0 + 1)[c];
    out[c] = static_cast<uchar>(std::lround(v));
  }
  return out;
}

}  // namespace

SyntheticScene::SyntheticScene(unsigned seed) {
  std::mt19937 rng(seed);
  using V = Eigen::Vector3d;
  // A room seen from the origin looking along +z (y down, as camera coordinates).
  quads_ = {
      {V(-3.0, -2.0, 4.5), V(6.0, 0, 0), V(0, 3.2, 0), 0},    // back wall
      {V(-3.0, 1.2, 0.5), V(6.0, 0, 0), V(0, 0, 4.0), 1},     // floor
      {V(-2.2, -2.0, 0.5), V(0, 0, 4.0), V(0, 3.2, 0), 2},    // left wall
      {V(2.4, -2.0, 0.5), V(0, 0, 4.0), V(0, 3.2, 0), 3},     // right wall
      {V(-0.9, 0.2, 2.4), V(0.8, 0, 0), V(0, 1.0, 0), 4},     // box front
      {V(0.6, -0.6, 3.2), V(0.9, 0, -0.3), V(0, 1.8, 0), 5},  // slanted panel
      {V(-1.6, -0.9, 3.0), V(0.7, 0, 0.2), V(0, 0.7, 0), 0},  // picture on a stand
  };
  for (int i = 0; i < 6; ++i) textures_.push_back(makeTexture(rng));
}

SE3Quat SyntheticScene::defaultMotion() {
  const Eigen::AngleAxisd rotation(3.0 * M_PI / 180.0, Eigen::Vector3d(0.3, 1.0, 0.1).normalized());
  return SE3Quat(rotation.toRotationMatrix(), Eigen::Vector3d(-0.11, 0.02, 0.05));
}

bool SyntheticScene::castRay(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                             double* distance, cv::Vec3b* colour) const {
  double best = std::numeric_limits<double>::infinity();
  const Quad* hit = nullptr;
  double hit_s = 0, hit_t = 0;
  for (const Quad& q : quads_) {
    const Eigen::Vector3d n = q.axis_u.cross(q.axis_v);
    const double denom = n.dot(direction);
    if (std::abs(denom) < 1e-12) continue;
    const double lambda = n.dot(q.origin - origin) / denom;
    if (!(lambda > 1e-6) || lambda >= best) continue;
    const Eigen::Vector3d p = origin + lambda * direction - q.origin;
    const double s = p.dot(q.axis_u) / q.axis_u.squaredNorm();
    const double t = p.dot(q.axis_v) / q.axis_v.squaredNorm();
    if (s < 0 || s > 1 || t < 0 || t > 1) continue;
    best = lambda;
    hit = &q;
    hit_s = s;
    hit_t = t;
  }
  if (hit == nullptr) return false;
  *distance = best;
  // Texture scale: about 300 texels per metre along each axis.
  const cv::Mat& tex = textures_[hit->texture];
  const double x = std::fmod(hit_s * hit->axis_u.norm() * 300.0, tex.cols - 1.0);
  const double y = std::fmod(hit_t * hit->axis_v.norm() * 300.0, tex.rows - 1.0);
  *colour = sampleBilinear(tex, x, y);
  return true;
}

RenderedView SyntheticScene::render(const SyntheticCamera& camera, const SE3Quat& T_cw,
                                    const DepthNoise& noise, unsigned noise_seed) const {
  const int w = camera.width > 0 ? camera.width : 640;
  const int h = camera.height > 0 ? camera.height : 480;
  const PinholeCamera& k = camera.pinhole;
  // Normalised undistorted coordinates of every (distorted) output pixel.
  std::vector<cv::Point2f> pixels, normalised;
  pixels.reserve(static_cast<size_t>(w) * h);
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) pixels.emplace_back(static_cast<float>(u), static_cast<float>(v));
  const cv::Matx33d K(k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1);
  if (k.hasDistortion()) {
    const cv::Mat dist(1, 5, CV_64F, const_cast<double*>(k.distortion.data()));
    cv::undistortPoints(pixels, normalised, K, dist);
  } else {
    normalised.reserve(pixels.size());
    for (const cv::Point2f& p : pixels) {
      normalised.emplace_back(static_cast<float>((p.x - k.cx) / k.fx),
                              static_cast<float>((p.y - k.cy) / k.fy));
    }
  }
  const SE3Quat T_wc = T_cw.inverse();
  const Eigen::Matrix3d R_wc = T_wc.rotation().toRotationMatrix();
  const Eigen::Vector3d centre = T_wc.translation();

  RenderedView view;
  view.colour.create(h, w, CV_8UC3);
  view.depth.create(h, w, CV_16UC1);
  std::mt19937 rng(noise_seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const cv::Point2f& n = normalised[static_cast<size_t>(v) * w + u];
      const Eigen::Vector3d ray_c(n.x, n.y, 1.0);  // z = 1: the hit distance is the depth
      double z = 0;
      cv::Vec3b colour(0, 0, 0);
      const bool hit = castRay(centre, R_wc * ray_c, &z, &colour);
      view.colour.at<cv::Vec3b>(v, u) = colour;
      const double noisy = z + noise.noise_k * z * z * gauss(rng);
      const bool hole = !hit || z > noise.max_range || unit(rng) < noise.hole_fraction;
      view.depth.at<uint16_t>(v, u) =
          hole ? 0
               : static_cast<uint16_t>(
                     std::clamp(std::lround(noisy * camera.depth_scale), 1L, 65535L));
    }
  }
  return view;
}

}  // namespace pnpba
