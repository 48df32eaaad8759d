// One rendered two-view RGB-D pair with its exact T_21: what render_synthetic writes and what
// the tests and the wide-baseline benchmark estimate.
#pragma once

#include <optional>

#include "pnpba/synthetic/sensor_effects.h"
#include "pnpba/synthetic/synthetic_scene.h"

namespace pnpba {

struct SyntheticPairOptions {
  unsigned seed = 7;  // scene textures; the depth noise of view k uses seed + k
  SceneLayout layout = SceneLayout::kOpenRoom;
  SceneTexture texture = SceneTexture::kRich;
  SyntheticCamera camera;
  DepthNoise noise;
  SensorEffects sensor;          // none by default
  std::optional<SE3Quat> T_21;   // none: SyntheticScene::defaultMotion()
  std::string validate() const;  // empty when valid
};

struct SyntheticPair {
  RenderedView view1, view2;
  SE3Quat T_21;
};

// Throws Error for invalid options.
SyntheticPair renderSyntheticPair(const SyntheticPairOptions& options);

}  // namespace pnpba
