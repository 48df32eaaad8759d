// registration_bench: the depth path's global registration alone (depth_registration.h) on the
// rendered wide-baseline sweep and the shared fr3_cabinet key frames: per set, the median and
// max of each sub-stage (clouds and descriptors, the coarse search, ICP) next to how often the
// returned pose is within 2 deg / 5 cm of the truth, and how often the truth is among the
// candidates it returns (the depth path's evidence chooses between those).
//
//   build/bench/registration_bench [--seeds 1]
//       [--sets sweep-rich,sweep-poor,sweep-cabinet,cabinet,cabinet-wide]
//                                  [--method ransac|open3d-ransac|fast|candidates] [--fine-voxel M]
//                                  [--icp-iterations N] [--voxel M] [--stride N] [--max-candidates
//                                  N] [--fpfh-neighbours N] [--max-points N]
//                                  [--verbose]
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "guarded_main.h"
#include "percentile.h"
#include "pnpba/evaluation/evaluation.h"
#include "pnpba/evaluation/tum_dataset.h"
#include "pnpba/pipeline/camera.h"
#include "pnpba/pipeline/depth_registration.h"
#include "wide_baseline_pairs.h"

namespace {

using pnpba::bench::percentile;

struct Tally {
  std::vector<double> total, prepare, global, icp;
  int pairs = 0, returned = 0, ok = 0, seed_ok = 0, truth_among = 0, seed_among = 0, candidates = 0;
};

// Within 2 deg / 5 cm (a right pose), or within a voxel-scale step (5 deg / 25 cm: a seed the
// depth path's alignment refines to the truth, which a registration without ICP is meant to give).
bool within(const pnpba::SE3Quat& T, const pnpba::SE3Quat& truth, double deg = 2.0,
            double cm = 5.0) {
  const pnpba::PoseError e = pnpba::relativePoseError(T, truth);
  return e.rot_deg <= deg && e.trans_cm <= cm;
}

bool g_verbose = false;
pnpba::DepthRegistrationOptions g_options;

void run(const std::string& label, const cv::Mat& depth1, const cv::Mat& depth2,
         const pnpba::Camera& camera, const pnpba::SE3Quat& truth, Tally* t) {
  const pnpba::DepthRegistration r =
      pnpba::registerDepthImages(depth1, depth2, camera.pinhole, camera.depth_scale, g_options);
  ++t->pairs;
  t->total.push_back(r.time_ms);
  t->prepare.push_back(r.prepare_ms);
  t->global.push_back(r.global_ms);
  t->icp.push_back(r.icp_ms);
  bool among = false, seed_among = false;
  for (const auto& c : r.candidates) {
    among = among || within(c.T_21, truth);
    seed_among = seed_among || within(c.T_21, truth, 5.0, 25.0);
  }
  t->seed_among += seed_among;
  t->candidates += static_cast<int>(r.candidates.size());
  t->truth_among += among;
  if (r.ok) {
    ++t->returned;
    t->ok += within(r.T_21, truth);
    t->seed_ok += within(r.T_21, truth, 5.0, 25.0);
  }
  if (g_verbose) {
    const pnpba::PoseError e = pnpba::relativePoseError(r.T_21, truth);
    std::printf(
        "%-22s %7.1f ms (prep %6.1f global %6.1f icp %6.1f) %s %6.2f deg %6.1f cm, "
        "%zu candidates, truth %s, points %d / %d at voxel %.1f cm\n",
        label.c_str(), r.time_ms, r.prepare_ms, r.global_ms, r.icp_ms, r.ok ? "pose" : "none",
        e.rot_deg, e.trans_cm, r.candidates.size(), among ? "among" : "missing", r.points1,
        r.points2, 100 * r.voxel_m);
  }
}

void print(const std::string& name, const Tally& t) {
  std::printf(
      "%-14s %4d pairs  total p50 %7.1f p95 %7.1f max %7.1f ms | prepare %6.1f global %6.1f "
      "icp %6.1f (medians) | within 2deg/5cm %3d, 5deg/25cm %3d, among the candidates %3d and "
      "%3d (%.1f each)\n",
      name.c_str(), t.pairs, percentile(t.total, 0.5), percentile(t.total, 0.95),
      percentile(t.total, 1.0), percentile(t.prepare, 0.5), percentile(t.global, 0.5),
      percentile(t.icp, 0.5), t.ok, t.seed_ok, t.truth_among, t.seed_among,
      t.pairs ? static_cast<double>(t.candidates) / t.pairs : 0.0);
}

}  // namespace

// The bench itself (main: guarded_main.h).
static int benchMain(int argc, char** argv) {
  CLI::App app{"The depth registration alone: time per sub-stage and accuracy per set"};
  int seeds = 1;
  std::string sets_text = "sweep-rich,sweep-poor,sweep-cabinet,cabinet,cabinet-wide";
  app.add_option("--seeds", seeds, "rendered pairs per sweep cell")->check(CLI::Range(1, 10));
  app.add_option("--sets", sets_text, "comma-separated sets")
      ->check([](const std::string& text) {
        std::stringstream list(text);
        for (std::string s; std::getline(list, s, ',');) {
          if (s != "sweep-rich" && s != "sweep-poor" && s != "sweep-cabinet" && s != "cabinet" &&
              s != "cabinet-wide") {
            return "unknown set '" + s +
                   "' (sweep-rich, sweep-poor, sweep-cabinet, cabinet, cabinet-wide)";
          }
        }
        return std::string();
      })
      ->capture_default_str();
  app.add_flag("--verbose", g_verbose, "a line per pair");
  std::string method = pnpba::toString(g_options.method);
  app.add_option("--method", method,
                 "global registration: ransac, open3d-ransac, fast or candidates")
      ->check(CLI::IsMember({"ransac", "open3d-ransac", "fast", "candidates"}));
  app.add_option("--fine-voxel", g_options.fine_voxel_m, "the last ICP's voxel (m; 0: none)");
  app.add_option("--icp-iterations", g_options.icp_iterations, "ICP iterations per stage");
  app.add_option("--voxel", g_options.voxel_m, "the descriptors' voxel ceiling (m)");
  app.add_option("--stride", g_options.pixel_stride, "back-project every n-th pixel");
  app.add_option("--fpfh-neighbours", g_options.fpfh_neighbours,
                 "neighbours an FPFH descriptor gathers at most");
  app.add_option("--max-points", g_options.max_points,
                 "cloud 1 at most about this many points (0: no limit)");
  app.add_option("--max-candidates", g_options.candidates.max_candidates,
                 "distinct poses the candidates search returns at most");
  CLI11_PARSE(app, argc, argv);
  g_options.method = pnpba::parseGlobalRegistration(method);
  std::vector<std::string> sets;
  std::stringstream list(sets_text);
  for (std::string s; std::getline(list, s, ',');) sets.push_back(s);
  auto wanted = [&](const std::string& s) {
    return std::find(sets.begin(), sets.end(), s) != sets.end();
  };
  using pnpba::bench::SweepScene;
  for (SweepScene scene : {SweepScene::kRich, SweepScene::kPoor, SweepScene::kCabinet}) {
    const std::string name = std::string("sweep-") + pnpba::bench::toString(scene);
    if (!wanted(name)) continue;
    Tally t;
    for (double deg : {0.0, 10.0, 20.0, 30.0, 45.0, 60.0}) {
      for (double metres : {0.0, 0.25, 0.5, 1.0, 1.5, 2.0}) {
        for (int s = 0; s < seeds; ++s) {
          const pnpba::SyntheticPair sp =
              pnpba::renderSyntheticPair(pnpba::bench::wideBaselinePair(scene, deg, metres, s));
          char label[64];
          std::snprintf(label, sizeof label, "%s %2.0f %3.2f %d", name.c_str(), deg, metres, s);
          run(label, sp.view1.depth, sp.view2.depth, pnpba::Camera{}, sp.T_21, &t);
        }
      }
    }
    print(name, t);
  }
  // The shared fr3_cabinet key frames: neighbours and three apart (cabinet), five and eight
  // apart (cabinet-wide: 26-74 degrees, 0.5-1.5 m, where the registration must find the pose).
  const std::string folder = std::string(PNPBA_SHARED_DATA) + "/tum_fr3_cabinet_keyframes";
  for (const auto& [name, gaps] :
       {std::pair<std::string, std::vector<int>>{"cabinet", {1, 3}}, {"cabinet-wide", {5, 8}}}) {
    if (!wanted(name) || !std::filesystem::exists(folder)) continue;
    const pnpba::TumSequence seq = pnpba::loadTumSequence(folder);
    const pnpba::Camera camera =
        pnpba::loadCameraYaml(std::string(PNPBA_SOURCE_DIR) + "/data/cameras/tum_fr3.yaml");
    Tally t;
    const int n = static_cast<int>(seq.frames.size());
    for (int i = 0; i < n; ++i) {
      for (int k : gaps) {
        const int j = i + k;
        if (j >= n || !seq.ground_truth[i] || !seq.ground_truth[j]) continue;
        run(name + " " + std::to_string(i) + "-" + std::to_string(j),
            cv::imread(folder + "/" + seq.frames[i].depth, cv::IMREAD_UNCHANGED),
            cv::imread(folder + "/" + seq.frames[j].depth, cv::IMREAD_UNCHANGED), camera,
            pnpba::relativePose(*seq.ground_truth[i], *seq.ground_truth[j]), &t);
      }
    }
    print(name, t);
  }
  return 0;
}

int main(int argc, char** argv) {
  return pnpba::bench::guardedMain("registration_bench", benchMain, argc, argv);
}
