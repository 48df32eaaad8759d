// One rendered two-view RGB-D pair with its exact T_21: what render_synthetic writes and what
// the tests and the wide-baseline benchmark estimate.
#pragma once

#include <optional>

#include "pnpba/synthetic/sensor_effects.h"
#include "pnpba/synthetic/synthetic_scene.h"

namespace pnpba {

// A box that moves between the two views (SyntheticScene::addObject): a person walking through
// the view, as in TUM's fr3 walking sequences. Coordinates are camera 1's.
struct MovingObject {
  Eigen::Vector3d low = Eigen::Vector3d(-0.25, -0.4, 1.5), size = Eigen::Vector3d(0.5, 1.7, 0.3);
  SE3Quat motion;  // between view 1 and view 2, about the box's centre
  unsigned texture_seed = 4242;
};

struct SyntheticPairOptions {
  unsigned seed = 7;  // scene textures; the depth noise of view k uses seed + k
  SceneLayout layout = SceneLayout::kOpenRoom;
  SceneTexture texture = SceneTexture::kRich;
  SyntheticCamera camera;
  DepthNoise noise;
  SensorEffects sensor;                       // none by default
  std::optional<SE3Quat> T_21;                // none: SyntheticScene::defaultMotion()
  std::optional<MovingObject> moving_object;  // none: a static scene
  std::string validate() const;               // empty when valid
};

struct SyntheticPair {
  RenderedView view1, view2;
  SE3Quat T_21;
};

// Throws Error for invalid options.
SyntheticPair renderSyntheticPair(const SyntheticPairOptions& options);

}  // namespace pnpba
