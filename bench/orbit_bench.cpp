// orbit_bench: the two-view pose around a free-standing object seen from all round. Renders the
// free cabinet (SceneLayout::kFreeCabinet: a plain cabinet alone on a floor, three dark handles on
// one face) through a Kinect-like sensor with JPEG colour, camera 2 circling it by each angle
// (SyntheticScene::orbitMotion), and counts per angle ok / refused / off / wrong (pose_tally.h).
// A half turn about the cabinet's vertical axis maps all but the handles onto themselves, so the
// depths fit camera 2 on either side of it: the alias TUM fr3_cabinet's far-side pairs show
// (docs/two_view.md, "Farther round"). This is where a rule against it is to be calibrated.
//
//   build/bench/orbit_bench [--angles 0,30,...,180] [--seeds 3] [--methods default,opencv]
//       [--verbose] [--json FILE]
#include <CLI/CLI.hpp>
#include <cstdio>
#include <map>
#include <nlohmann/json.hpp>
#include <vector>

#include "guarded_main.h"
#include "percentile.h"
#include "pnpba/core/output_file.h"
#include "pnpba/pipeline/depth_registration.h"
#include "pnpba/synthetic/synthetic_pair.h"
#include "pose_tally.h"
#include "wide_baseline_pairs.h"

namespace {

using pnpba::bench::percentile;

using Tally = pnpba::bench::PoseTally;

// The free cabinet with camera 2 `degrees` round it, a seed's textures and noise: the sweep
// cabinet's sensor (Kinect-like depth and JPEG colour).
pnpba::SyntheticPairOptions orbitPair(double degrees, int seed_index) {
  pnpba::SyntheticPairOptions o;
  o.seed = 3000 + 97 * seed_index + static_cast<unsigned>(degrees * 7);
  o.layout = pnpba::SceneLayout::kFreeCabinet;
  o.texture = pnpba::SceneTexture::kPoor;
  o.sensor = pnpba::SensorEffects::kinectLike();
  o.noise.noise_k = 0.0025;
  o.noise.max_range = 8.0;
  o.T_21 = pnpba::SyntheticScene::orbitMotion(degrees);
  return o;
}

int run(int argc, char** argv) {
  CLI::App app{"The two-view pose around a free-standing cabinet seen from all round."};
  std::vector<double> angles{0, 30, 60, 90, 120, 150, 165, 180};
  pnpba::bench::AccuracyRunOptions common;
  common.seeds = 3;
  app.add_option("--angles", angles, "camera 2's turn round the cabinet (degrees)")
      ->delimiter(',')
      ->capture_default_str()
      ->check(CLI::Range(-360.0, 360.0));
  pnpba::bench::addAccuracyRunOptions(app, &common, "pairs per angle", "{\"angles\": [...]}");
  std::vector<std::string> methods;
  if (const int exit = pnpba::bench::parseAccuracyRun(app, argc, argv, common, &methods);
      exit >= 0) {
    return exit;
  }

  pnpba::preloadDepthRegistration();  // its one-time load out of the pairs' times
  const pnpba::SyntheticCamera render_camera = pnpba::bench::sensorCamera("tum");
  const pnpba::Camera camera = pnpba::bench::estimationCamera(render_camera);
  nlohmann::json out = nlohmann::json::array();
  std::printf("%-8s %-8s %4s %8s %4s %6s %7s %7s\n", "angle", "method", "ok", "refused", "off",
              "wrong", "p50 ms", "max ms");
  for (double angle : angles) {
    std::map<std::string, Tally> tally;
    for (int s = 0; s < common.seeds; ++s) {
      pnpba::SyntheticPairOptions o = orbitPair(angle, s);
      o.camera = render_camera;
      const pnpba::SyntheticPair p = pnpba::renderSyntheticPair(o);
      for (const std::string& method : methods) {
        const pnpba::TwoViewResult r = pnpba::bench::estimateWith(method, p, camera);
        const std::string verdict = pnpba::bench::tallyResult(r, p.T_21, &tally[method]);
        if (common.verbose) {
          std::printf("  %6.1f deg seed %d %-7s %s, path %s, consistency %.3f\n", angle, s,
                      method.c_str(), verdict.c_str(), r.path.c_str(), r.depth_consistency);
        }
      }
    }
    for (const std::string& method : methods) {
      const Tally& t = tally[method];
      std::printf("%-8.1f %-8s %4d %8d %4d %6d %7.1f %7.1f\n", angle, method.c_str(), t.ok,
                  t.refused, t.off, t.wrong, percentile(t.times_ms, 0.5),
                  percentile(t.times_ms, 1.0));
      nlohmann::json row = {{"angle_deg", angle}, {"method", method}, {"pairs", common.seeds}};
      row.update(pnpba::bench::tallyJson(t));
      out.push_back(row);
    }
    std::fflush(stdout);
  }
  pnpba::bench::writeRows(common, "angles", out);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return pnpba::bench::guardedMain("orbit_bench", run, argc, argv);
}
