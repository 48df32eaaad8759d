#include "pnpba/synthetic/synthetic_pair.h"

#include <cmath>

#include "pnpba/core/error.h"

namespace pnpba {

std::string SyntheticPairOptions::validate() const {
  const PinholeCamera& k = camera.pinhole;
  for (double v : {k.fx, k.fy, k.cx, k.cy}) {
    if (!std::isfinite(v)) return "camera intrinsics must be finite";
  }
  if (!(k.fx > 0) || k.fy == 0) return "camera: fx must be > 0 and fy non-zero";
  if (camera.width < 16 || camera.height < 16) return "camera: image size must be >= 16x16";
  if (!(camera.depth_scale > 0) || !std::isfinite(camera.depth_scale)) {
    return "depth scale must be > 0";
  }
  if (!(noise.noise_k >= 0) || !(noise.hole_fraction >= 0 && noise.hole_fraction < 1) ||
      !(noise.max_range > 0)) {
    return "depth noise: k >= 0, holes in [0, 1), max range > 0";
  }
  if (camera.colour_samples < 1 || camera.colour_samples > 8) {
    return "camera: colour samples per pixel side must be in [1, 8]";
  }
  if (camera.colour_samples > 1 && k.hasDistortion()) {
    return "camera: colour samples > 1 need a camera without distortion";
  }
  if (T_21 && !T_21->to_homogeneous_matrix().allFinite()) return "motion must be finite";
  if (moving_object && (!moving_object->low.allFinite() || !(moving_object->size.minCoeff() > 0) ||
                        !moving_object->motion.to_homogeneous_matrix().allFinite())) {
    return "moving object: a finite box of positive sizes and a finite motion";
  }
  const std::string sensor_problem = sensor.validate();
  if (!sensor_problem.empty()) return "sensor effects: " + sensor_problem;
  return "";
}

SyntheticPair renderSyntheticPair(const SyntheticPairOptions& o) {
  const std::string problem = o.validate();
  if (!problem.empty()) throw Error(problem);
  SyntheticScene scene(o.seed, o.layout, o.texture);
  std::optional<SyntheticScene> moved;  // view 2's scene when an object moves
  if (o.moving_object) {
    const MovingObject& m = *o.moving_object;
    moved = scene.withObjectMoved(scene.addObject(m.low, m.size, m.texture_seed), m.motion);
  }
  SyntheticPair pair;
  pair.T_21 = o.T_21 ? *o.T_21 : SyntheticScene::defaultMotion();
  pair.view1 = scene.render(o.camera, SE3Quat(), o.noise, o.seed + 1);
  pair.view2 = (moved ? *moved : scene).render(o.camera, pair.T_21, o.noise, o.seed + 2);
  applySensorEffects(o.sensor, o.camera.depth_scale, &pair.view1);
  applySensorEffects(o.sensor, o.camera.depth_scale, &pair.view2);
  return pair;
}

}  // namespace pnpba
