#include "pnpba/synthetic/synthetic_scene.h"

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

namespace pnpba {

namespace {

// The cabinet of both cabinet layouts: 1.2 x 1.0 x 0.7 m on the floor at y = 1.0, its front face at
// z = 2.6 toward camera 1.
const Eigen::Vector3d kCabinetLow(-0.6, 0.0, 2.6), kCabinetSize(1.2, 1.0, 0.7);
constexpr int kHandleTexture = 3;  // the free cabinet's handles

constexpr int kTextureSize = 1024;
// kTiled's tile: 0.5 m at castRay's 300 texels per metre.
constexpr int kTiledPeriodTexels = 150;

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

// The texture's top-left `tile` x `tile` texels repeated over the whole texture.
cv::Mat tiled(const cv::Mat& texture, int tile) {
  const int copies = (std::max(texture.rows, texture.cols) + tile - 1) / tile;
  cv::Mat repeated;
  cv::repeat(texture(cv::Rect(0, 0, tile, tile)), copies, copies, repeated);
  return repeated(cv::Rect(0, 0, texture.cols, texture.rows)).clone();
}

// A plain surface: one flat colour with sensor-like noise far below FAST's threshold: no
// corners inside, edges only where surfaces meet.
cv::Mat makePlainTexture(std::mt19937& rng) {
  std::uniform_int_distribution<int> shade(70, 200);
  const cv::Vec3d base(shade(rng), shade(rng), shade(rng));
  std::normal_distribution<double> noise(0.0, 1.5);
  cv::Mat t(kTextureSize, kTextureSize, CV_8UC3);
  for (int y = 0; y < kTextureSize; ++y) {
    for (int x = 0; x < kTextureSize; ++x) {
      const double n = noise(rng);
      for (int c = 0; c < 3; ++c) t.at<cv::Vec3b>(y, x)[c] = cv::saturate_cast<uchar>(base[c] + n);
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

SyntheticScene::SyntheticScene(unsigned seed, SceneLayout layout, SceneTexture texture) {
  std::mt19937 rng(seed);
  if (layout == SceneLayout::kOpenRoom) {
    buildOpenRoom();
  } else {
    if (layout == SceneLayout::kClosedRoom) {
      buildClosedRoom();
    } else if (layout == SceneLayout::kCabinet) {
      buildCabinet();
    } else if (layout == SceneLayout::kStructure) {
      buildStructure();
    } else if (layout == SceneLayout::kCorridor) {
      buildCorridor();
    } else if (layout == SceneLayout::kPoster) {
      buildPoster();
    } else {
      buildFreeCabinet();
    }
    shade_faces_ = true;
  }
  int used = 0;
  for (const Quad& q : quads_) used = std::max(used, q.texture + 1);
  for (int i = 0; i < used; ++i) {
    // In a poor scene, and on the poster's wall, only texture 0 (the poster's) has corners.
    const bool plain =
        ((texture == SceneTexture::kPoor || layout == SceneLayout::kPoster) && i != 0) ||
        layout == SceneLayout::kCabinet || layout == SceneLayout::kFreeCabinet ||
        layout == SceneLayout::kStructure || layout == SceneLayout::kCorridor;
    if (plain) {
      textures_.push_back(makePlainTexture(rng));
    } else if (texture == SceneTexture::kTiled) {
      textures_.push_back(tiled(makeTexture(rng), kTiledPeriodTexels));
    } else {
      textures_.push_back(makeTexture(rng));
    }
  }
  if (layout == SceneLayout::kFreeCabinet) textures_[kHandleTexture] *= 0.35;
}

void SyntheticScene::buildOpenRoom() {
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
}

void SyntheticScene::addBox(const Eigen::Vector3d& low, const Eigen::Vector3d& size, int texture) {
  using V = Eigen::Vector3d;
  const V x(size.x(), 0, 0), y(0, size.y(), 0), z(0, 0, size.z());
  const V high = low + size;
  quads_.push_back({low, x, y, texture});                            // face z = low
  quads_.push_back({V(low.x(), low.y(), high.z()), x, y, texture});  // face z = high
  quads_.push_back({low, z, y, texture});                            // face x = low
  quads_.push_back({V(high.x(), low.y(), low.z()), z, y, texture});  // face x = high
  quads_.push_back({low, x, z, texture});                            // top (y = low: y points down)
  quads_.push_back({V(low.x(), high.y(), low.z()), x, z, texture});  // bottom
}

void SyntheticScene::buildClosedRoom() {
  using V = Eigen::Vector3d;
  // x: -4.5 .. 4.5, y (down): -2.2 (ceiling) .. 1.3 (floor), z: -3.5 .. 6.
  const double x0 = -4.5, x1 = 4.5, y0 = -2.2, y1 = 1.3, z0 = -3.5, z1 = 6.0;
  const V dx(x1 - x0, 0, 0), dy(0, y1 - y0, 0), dz(0, 0, z1 - z0);
  quads_ = {
      {V(x0, y0, z1), dx, dy, 1},  // far wall
      {V(x0, y0, z0), dx, dy, 2},  // near wall (behind camera 1)
      {V(x0, y0, z0), dz, dy, 3},  // left wall
      {V(x1, y0, z0), dz, dy, 4},  // right wall
      {V(x0, y1, z0), dx, dz, 5},  // floor
      {V(x0, y0, z0), dx, dz, 6},  // ceiling
  };
  quads_.push_back({V(-1.2, -1.0, 5.98), V(1.0, 0, 0), V(0, 0.8, 0), 0});  // poster, far wall
  quads_.push_back({V(4.48, -1.2, 1.0), V(0, 0, 1.2), V(0, 0.9, 0), 0});   // poster, right wall
  quads_.push_back({V(-4.48, -0.9, 2.5), V(0, 0, 0.9), V(0, 0.7, 0), 0});  // poster, left wall
  addBox(V(-1.0, 0.3, 2.6), V(0.9, 1.0, 0.8), 7);                          // box ahead
  addBox(V(1.2, -0.2, 3.6), V(1.1, 1.5, 0.7), 8);                          // cupboard
  addBox(V(-3.4, 0.5, 0.8), V(1.0, 0.8, 1.4), 9);                          // crate on the left
  addBox(V(2.6, 0.6, -1.5), V(1.2, 0.7, 1.0), 10);                         // crate behind, right
  addBox(V(-2.0, 0.55, -2.6), V(1.6, 0.1, 0.9), 11);                       // table top behind
  addBox(V(-0.3, 0.9, 1.2), V(0.5, 0.4, 0.5), 12);                         // small box on the floor
  quads_.push_back({V(0.3, -1.4, 4.4), V(1.0, 0, -0.6), V(0, 2.2, 0.3), 13});  // slanted panel
  quads_.push_back({V(-3.6, -1.8, 4.4), V(1.2, 0, 0.9), V(0, 2.4, 0), 14});    // corner panel
}

void SyntheticScene::buildCabinet() {
  using V = Eigen::Vector3d;
  // Floor at y = 1.0 (camera 1 a metre above it), back wall at z = 4.2, right wall at x = 2.4.
  quads_ = {
      {V(-4.0, 1.0, -1.0), V(6.4, 0, 0), V(0, 0, 5.2), 1},  // floor
      {V(-4.0, -2.0, 4.2), V(6.4, 0, 0), V(0, 3.0, 0), 2},  // back wall
      {V(2.4, -2.0, -1.0), V(0, 0, 5.2), V(0, 3.0, 0), 3},  // right wall
  };
  addBox(kCabinetLow, kCabinetSize, 4);  // the cabinet
}

void SyntheticScene::buildFreeCabinet() {
  using V = Eigen::Vector3d;
  quads_ = {{V(-8.0, 1.0, -5.0), V(16.0, 0, 0), V(0, 0, 16.0), 1}};  // floor, nothing else
  addBox(kCabinetLow, kCabinetSize, 2);
  // Three drawer handles, 2 cm proud of the front face, in a dark colour of their own (the
  // constructor darkens it): the only thing a half turn about the cabinet's vertical axis does not
  // map onto itself.
  for (double y : {0.2, 0.5, 0.8}) {
    addBox(V(-0.12, y - 0.02, 2.58), V(0.24, 0.04, 0.02), kHandleTexture);
  }
}

void SyntheticScene::buildStructure() {
  using V = Eigen::Vector3d;
  quads_ = {{V(-8.0, 1.0, -5.0), V(16.0, 0, 0), V(0, 0, 16.0), 1}};  // floor, nothing else
  // Eight panels from x = -2.4 to 2.4 m, their bottom edges on the floor, alternating between
  // z = 2.6 and 3.1 m: tan(40 deg) * 0.6 m is about 0.5 m of depth per panel.
  constexpr int kPanels = 8;
  constexpr double kWidth = 0.6, kHeight = 0.9, kNear = 2.6, kFar = 3.1;
  for (int i = 0; i < kPanels; ++i) {
    const double x0 = -0.5 * kPanels * kWidth + i * kWidth;
    const double z0 = i % 2 == 0 ? kNear : kFar, z1 = i % 2 == 0 ? kFar : kNear;
    quads_.push_back({V(x0, 1.0 - kHeight, z0), V(kWidth, 0, z1 - z0), V(0, kHeight, 0), 2});
  }
}

void SyntheticScene::buildCorridor() {
  using V = Eigen::Vector3d;
  quads_ = {
      {V(-8.0, 1.0, -5.0), V(16.0, 0, 0), V(0, 0, 8.0), 1},  // floor, up to the wall
      {V(-8.0, -2.0, 3.0), V(16.0, 0, 0), V(0, 3.0, 0), 2},  // the wall, 3 m ahead
  };
}

void SyntheticScene::buildPoster() {
  using V = Eigen::Vector3d;
  // castRay lays 300 texels a metre and wraps at the texture's last texel: 1023 of them, 3.41 m,
  // cover the poster once. It stands 1 mm proud of the wall, so that the nearer hit is its own.
  constexpr double kSide = 1023.0 / 300.0;
  quads_ = {
      {V(-0.5 * kSide, -0.5 * kSide, 2.999), V(kSide, 0, 0), V(0, kSide, 0), 0},  // the poster
      {V(-8.0, -6.0, 3.0), V(16.0, 0, 0), V(0, 12.0, 0), 1},                      // the wall
  };
}

SE3Quat SyntheticScene::orbitMotion(double degrees) {
  const Eigen::Vector3d centre = kCabinetLow + 0.5 * kCabinetSize;
  // y points down: a turn about -y is a turn about the vertical, counter-clockwise seen from above.
  const Eigen::Matrix3d R_wc2 =
      Eigen::AngleAxisd(degrees * M_PI / 180.0, -Eigen::Vector3d::UnitY()).toRotationMatrix();
  const Eigen::Vector3d camera2 = centre - R_wc2 * centre;  // camera 1's centre, turned about it
  return SE3Quat(R_wc2.transpose(), -R_wc2.transpose() * camera2);
}

int SyntheticScene::addObject(const Eigen::Vector3d& low, const Eigen::Vector3d& size,
                              unsigned texture_seed) {
  std::mt19937 rng(texture_seed);
  textures_.push_back(makeTexture(rng));
  const size_t first = quads_.size();
  addBox(low, size, static_cast<int>(textures_.size()) - 1);
  objects_.push_back({first, quads_.size(), low + 0.5 * size});
  return static_cast<int>(objects_.size()) - 1;
}

SyntheticScene SyntheticScene::withObjectMoved(int id, const SE3Quat& motion) const {
  SyntheticScene moved = *this;
  Object& object = moved.objects_.at(static_cast<size_t>(id));
  const Eigen::Matrix3d R = motion.rotation().toRotationMatrix();
  for (size_t i = object.first_quad; i < object.end_quad; ++i) {
    Quad& q = moved.quads_[i];
    q.origin = R * (q.origin - object.centre) + object.centre + motion.translation();
    q.axis_u = R * q.axis_u;
    q.axis_v = R * q.axis_v;
  }
  object.centre += motion.translation();
  return moved;
}

SE3Quat SyntheticScene::defaultMotion() {
  const Eigen::AngleAxisd rotation(3.0 * M_PI / 180.0, Eigen::Vector3d(0.3, 1.0, 0.1).normalized());
  return SE3Quat(rotation.toRotationMatrix(), Eigen::Vector3d(-0.11, 0.02, 0.05));
}

SE3Quat SyntheticScene::lookAtMotion(double rotation_deg, const Eigen::Vector3d& axis,
                                     double translation_m) {
  const Eigen::Matrix3d R_wc2 =
      Eigen::AngleAxisd(rotation_deg * M_PI / 180.0, axis.normalized()).toRotationMatrix();
  const Eigen::Vector3d target(0, 0, 3.0);  // 3 m ahead of camera 1
  const Eigen::Vector3d a = R_wc2.col(2);   // camera 2's optical axis in camera 1
  // Centre c = target - u a (u: distance to the target along the axis) on |c| = d, else the
  // point of the sphere closest to that line.
  const double u0 = a.dot(target);
  const Eigen::Vector3d foot = target - u0 * a;  // line point closest to camera 1
  const double d = translation_m;
  Eigen::Vector3d centre;
  if (foot.norm() >= d) {
    centre = foot.norm() > 1e-12 ? Eigen::Vector3d(foot.normalized() * d) : Eigen::Vector3d::Zero();
  } else {
    const double h = std::sqrt(d * d - foot.squaredNorm());
    // Of the two crossings keep the one at the more natural distance from the target.
    const double u = std::abs(u0 + h - 3.0) < std::abs(u0 - h - 3.0) ? u0 + h : u0 - h;
    centre = target - u * a;
  }
  // T_21 = T_2w with world = camera 1: X2 = R_wc2^T (X1 - centre).
  return SE3Quat(R_wc2.transpose(), -R_wc2.transpose() * centre);
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
  if (shade_faces_) {
    // Lambertian light from above-left-front: faces of one colour still differ, as lit rooms do.
    const Eigen::Vector3d n = hit->axis_u.cross(hit->axis_v).normalized();
    const double light =
        0.55 + 0.45 * std::abs(n.dot(Eigen::Vector3d(-0.3, -0.8, -0.5).normalized()));
    for (int c = 0; c < 3; ++c) (*colour)[c] = cv::saturate_cast<uchar>((*colour)[c] * light);
  }
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
  // The colour over the pixel: n x n rays on a regular grid inside it (a box filter, as a
  // sensor's pixel integrates); a ray that hits nothing counts as black, as the centre's does.
  const int samples = std::max(1, camera.colour_samples);
  auto pixelAverage = [&](int u, int v) {
    cv::Vec3d sum(0, 0, 0);
    for (int j = 0; j < samples; ++j) {
      for (int i = 0; i < samples; ++i) {
        const double du = (i + 0.5) / samples - 0.5, dv = (j + 0.5) / samples - 0.5;
        const Eigen::Vector3d ray((u + du - k.cx) / k.fx, (v + dv - k.cy) / k.fy, 1.0);
        double unused = 0;
        cv::Vec3b c(0, 0, 0);
        castRay(centre, R_wc * ray, &unused, &c);
        sum += cv::Vec3d(c[0], c[1], c[2]);
      }
    }
    sum /= static_cast<double>(samples * samples);
    return cv::Vec3b(cv::saturate_cast<uchar>(sum[0]), cv::saturate_cast<uchar>(sum[1]),
                     cv::saturate_cast<uchar>(sum[2]));
  };
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const cv::Point2f& n = normalised[static_cast<size_t>(v) * w + u];
      const Eigen::Vector3d ray_c(n.x, n.y, 1.0);  // z = 1: the hit distance is the depth
      double z = 0;
      cv::Vec3b colour(0, 0, 0);
      const bool hit = castRay(centre, R_wc * ray_c, &z, &colour);
      view.colour.at<cv::Vec3b>(v, u) = samples > 1 ? pixelAverage(u, v) : colour;
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
