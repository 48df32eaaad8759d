#include "pnpba/bal/bal_synthetic.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>

#include "pnpba/core/error.h"
#include "snavely_projection.h"

namespace pnpba {

namespace {

// Image half-size (BAL pixels are centred): a 1000 x 750 image.
constexpr double kHalfWidth = 500, kHalfHeight = 375;
constexpr double kRingRadius = 30;  // metres; the scene fills a 20 m cube at the centre

// Camera c of n on the ring: at angle 2 pi c / n, slightly varying height, looking at the
// centre. BAL cameras look down their -z axis: P = R X + t, visible when P.z < 0.
void ringCamera(int c, int n, std::mt19937_64& rng, double* params) {
  std::uniform_real_distribution<double> jitter(-1, 1);
  const double angle = 2 * M_PI * c / n;
  const Eigen::Vector3d centre(kRingRadius * std::cos(angle), 2 * jitter(rng),
                               kRingRadius * std::sin(angle));
  const Eigen::Vector3d target(jitter(rng), jitter(rng), jitter(rng));
  const Eigen::Vector3d back = (centre - target).normalized();  // camera +z
  const Eigen::Vector3d x = Eigen::Vector3d::UnitY().cross(back).normalized();
  const Eigen::Vector3d y = back.cross(x);
  Eigen::Matrix3d R;
  R.row(0) = x, R.row(1) = y, R.row(2) = back;
  const Eigen::AngleAxisd aa(R);
  Eigen::Map<Eigen::Vector3d> rotation(params), translation(params + 3);
  rotation = aa.angle() * aa.axis();
  translation = -R * centre;
  params[6] = 800 + 100 * jitter(rng);     // focal length, px
  params[7] = -0.05 + 0.02 * jitter(rng);  // k1
  params[8] = 0.01 + 0.005 * jitter(rng);  // k2
}

bool project(const double* camera, const Eigen::Vector3d& X, Eigen::Vector2d* uv) {
  const Eigen::Vector2d r = bal_detail::snavelyResidual(camera, X.data(), 0, 0);
  Eigen::Matrix3d R;
  bal_detail::rotationAndLeftJacobian(Eigen::Map<const Eigen::Vector3d>(camera), &R, nullptr);
  const double z = (R * X + Eigen::Map<const Eigen::Vector3d>(camera + 3)).z();
  *uv = r;
  return z < -1 && std::abs(r.x()) < kHalfWidth && std::abs(r.y()) < kHalfHeight;
}

}  // namespace

std::string BalSyntheticOptions::validate() const {
  if (cameras < 2) return "cameras must be >= 2";
  if (points < 1) return "points must be >= 1";
  if (observations_per_point < 2 || observations_per_point > cameras) {
    return "observations per point must be in [2, cameras]";
  }
  if (!(noise_px >= 0) || !std::isfinite(noise_px)) return "noise must be >= 0";
  if (!(start.rotation_sigma >= 0) || !(start.translation_sigma >= 0) ||
      !(start.point_sigma >= 0)) {
    return "perturbations must be >= 0";
  }
  return "";
}

BalSyntheticProblem generateBalProblem(const BalSyntheticOptions& o) {
  const std::string invalid = o.validate();
  if (!invalid.empty()) throw Error(invalid);
  std::mt19937_64 rng(o.seed);
  BalProblem truth;
  truth.num_cameras = o.cameras;
  truth.num_points = o.points;
  truth.cameras.resize(9 * o.cameras);
  for (int c = 0; c < o.cameras; ++c) ringCamera(c, o.cameras, rng, &truth.cameras[9 * c]);

  std::uniform_real_distribution<double> in_scene(-10, 10);
  std::uniform_int_distribution<int> any_camera(0, o.cameras - 1);
  std::normal_distribution<double> noise(0, o.noise_px);
  const int K = o.observations_per_point;
  std::vector<int> seen_by;
  std::vector<Eigen::Vector2d> pixels;
  truth.points.reserve(3 * o.points);
  truth.observations.reserve(static_cast<size_t>(o.points) * K);
  std::vector<char> camera_used(o.cameras, 0);
  for (int q = 0; q < o.points;) {
    // A track: from a random camera outwards along the ring, the first K that see the point.
    const Eigen::Vector3d X(in_scene(rng), 0.5 * in_scene(rng), in_scene(rng));
    const int c0 = any_camera(rng);
    seen_by.clear(), pixels.clear();
    for (int step = 0; step < 4 * K + 8 && static_cast<int>(seen_by.size()) < K; ++step) {
      const int offset = (step + 1) / 2 * (step % 2 ? 1 : -1);
      const int c = ((c0 + offset) % o.cameras + o.cameras) % o.cameras;
      if (step > 0 && offset == 0) continue;
      Eigen::Vector2d uv;
      if (std::find(seen_by.begin(), seen_by.end(), c) == seen_by.end() &&
          project(&truth.cameras[9 * c], X, &uv)) {
        seen_by.push_back(c), pixels.push_back(uv);
      }
    }
    if (static_cast<int>(seen_by.size()) < K) continue;  // not seen often enough: another point
    for (int k = 0; k < 3; ++k) truth.points.push_back(X[k]);
    for (int i = 0; i < K; ++i) {
      truth.observations.push_back(
          {seen_by[i], q, pixels[i].x() + noise(rng), pixels[i].y() + noise(rng)});
      camera_used[seen_by[i]] = 1;
    }
    ++q;
  }
  for (int c = 0; c < o.cameras; ++c) {
    if (!camera_used[c]) throw Error("camera " + std::to_string(c) + " sees no point: add points");
  }
  BalSyntheticProblem out{truth, truth};
  perturbBal(out.start, o.start);
  return out;
}

}  // namespace pnpba
