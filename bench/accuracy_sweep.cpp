// accuracy_sweep: accuracy and time of the two-view pipeline on synthetic pairs with exact
// ground truth, per ORB feature count and BA mode: the measurements behind the defaults
// (docs/two_view.md "What each choice bought").
//
//   build/bench/accuracy_sweep [num_pairs=8]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <random>

#include "guarded_main.h"
#include "pnpba/pipeline/two_view.h"
#include "pnpba/synthetic/synthetic_scene.h"

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[v.size() / 2];
}

}  // namespace

// The bench itself (main: guarded_main.h).
static int benchMain(int argc, char** argv) {
  using namespace pnpba;
  const int num_pairs = argc > 1 ? std::atoi(argv[1]) : 8;
  Camera camera;
  camera.width = 640;
  camera.height = 480;
  const SyntheticCamera render_camera{camera.pinhole, camera.width, camera.height,
                                      camera.depth_scale};
  const SyntheticScene scene(7);
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  struct Pair {
    RenderedView v1, v2;
    SE3Quat T;
  };
  std::vector<Pair> pairs;
  const RenderedView first = scene.render(render_camera, SE3Quat(), DepthNoise{}, 100);
  for (int i = 0; i < num_pairs; ++i) {
    // Motions like consecutive-to-distant video frames: 1-6 degrees, 2-20 cm.
    const double angle = (1.0 + 5.0 * (unit(rng) + 1) / 2) * M_PI / 180;
    const Eigen::Vector3d axis = Eigen::Vector3d(unit(rng), unit(rng), unit(rng)).normalized();
    const Eigen::Vector3d t = (0.02 + 0.18 * (unit(rng) + 1) / 2) *
                              Eigen::Vector3d(unit(rng), unit(rng), 0.5 * unit(rng)).normalized();
    const SE3Quat T(Eigen::AngleAxisd(angle, axis).toRotationMatrix(), t);
    pairs.push_back({first, scene.render(render_camera, T, DepthNoise{}, 200 + i), T});
  }
  std::printf("%-8s %-10s %12s %12s %12s %10s\n", "features", "ba", "median_deg", "median_mm",
              "max_mm", "median_ms");
  for (int features : {500, 1000, 1500, 2000}) {
    for (BundleMode mode : {BundleMode::kNone, BundleMode::kPose, BundleMode::kRgbd}) {
      std::vector<double> rot, trans, ms;
      for (const Pair& p : pairs) {
        TwoViewOptions o;
        o.orb.num_features = features;
        o.refinement.mode = mode;
        const TwoViewResult r =
            estimateTwoView(p.v1.colour, p.v1.depth, p.v2.colour, p.v2.depth, camera, o);
        if (!r.ok) {
          rot.push_back(180), trans.push_back(1e3), ms.push_back(r.times_ms.total_ms);
          continue;
        }
        rot.push_back((r.T_21 * p.T.inverse()).log().head<3>().norm() * 180 / M_PI);
        trans.push_back((r.T_21.translation() - p.T.translation()).norm() * 1e3);
        ms.push_back(r.times_ms.total_ms);
      }
      std::printf("%-8d %-10s %12.4f %12.2f %12.2f %10.1f\n", features, toString(mode), median(rot),
                  median(trans), *std::max_element(trans.begin(), trans.end()), median(ms));
    }
  }
  return 0;
}

int main(int argc, char** argv) {
  return pnpba::bench::guardedMain("accuracy_sweep", benchMain, argc, argv);
}
