// The wide-baseline sweep's rendered pairs, shared by the benches and tests that use them:
// the closed room with rich or poor texture, camera 2 turned `deg` about a random near-vertical
// axis and moved `metres` while looking at the room (SyntheticScene::lookAtMotion), one seed
// per index.
#pragma once

#include <random>

#include "pnpba/synthetic/synthetic_pair.h"
#include "pnpba/synthetic/synthetic_scene.h"

namespace pnpba::bench {

inline SyntheticPairOptions wideBaselinePair(bool poor_texture, double deg, double metres,
                                             int seed_index) {
  const unsigned seed = 1000 + 97 * seed_index + static_cast<unsigned>(deg * 7 + metres * 100);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> tilt(-0.3, 0.3);
  const Eigen::Vector3d axis(tilt(rng), rng() % 2 ? 1.0 : -1.0, tilt(rng));
  SyntheticPairOptions o;
  o.seed = seed;
  o.layout = SceneLayout::kClosedRoom;
  o.texture = poor_texture ? SceneTexture::kPoor : SceneTexture::kRich;
  o.noise.max_range = 8.0;
  o.T_21 = SyntheticScene::lookAtMotion(deg, axis, metres);
  return o;
}

}  // namespace pnpba::bench
