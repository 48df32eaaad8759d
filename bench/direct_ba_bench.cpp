// direct_ba_bench: the direct-BA exercise data (7 images, 4118 points, 28,826 edges), Huber
// delta 1, pose 0 fixed, active set re-decided every 10 iterations; xyz and inverse-depth
// points; 1 thread (native LM) and 2 threads (Ceres, threaded Schur). Medians over
// repetitions of total time, time per iteration, final cost and largest point motion.
//
//   build/bench/direct_ba_bench [iterations=30] [repetitions=3]
#include <algorithm>
#include <cstdio>

#include "direct_ba_data.h"
#include "guarded_main.h"
#include "pnpba/direct/direct_ba.h"
#include "rendered_direct_scene.h"

// The bench itself (main: guarded_main.h).
static int benchMain(int argc, char** argv) {
  const int iterations = argc > 1 ? std::atoi(argv[1]) : 30;
  const int repetitions = argc > 2 ? std::atoi(argv[2]) : 3;
  const pnpba::DirectBaProblem original = pnpba::test::loadDirectBaExercise(PNPBA_SHARED_DATA);
  std::printf("%-14s %7s %9s %12s %12s %6s %10s\n", "points", "threads", "total_s", "ms/iteration",
              "final_cost", "iters", "max_move_m");
  for (bool inverse_depth : {false, true}) {
    for (int threads : {1, 2}) {
      std::vector<double> totals, per_it, costs, moves;
      int its = 0;
      for (int r = 0; r < repetitions; ++r) {
        pnpba::DirectBaProblem p = original;
        pnpba::DirectBaOptions o;
        o.huber_delta = 1.0;
        o.iterations = iterations;
        o.inverse_depth = inverse_depth;
        o.threads = threads;
        const pnpba::DirectBaSummary s = pnpba::solveDirectBa(p, o);
        totals.push_back(s.time_s);
        per_it.push_back(1000.0 * s.time_s / std::max(1, s.iterations));
        costs.push_back(s.final_cost);
        moves.push_back(s.max_point_motion_m);
        its = s.iterations;
      }
      auto med = [](std::vector<double> v) {
        std::sort(v.begin(), v.end());
        return v[v.size() / 2];
      };
      std::printf("%-14s %7d %9.2f %12.1f %12.6e %6d %10.3f\n",
                  inverse_depth ? "inverse_depth" : "xyz", threads, med(totals), med(per_it),
                  med(costs), its, med(moves));
      std::fflush(stdout);
    }
  }

  // Patch size, on the rendered scene with exact ground truth (poses perturbed 1.1 deg /
  // 3.5 cm, points 2 cm): centred 2x2, 3x3 and the full 4x4 window of each patch.
  std::printf("\nrendered scene, 60 iterations: patch  max_rot_deg  max_centre_mm  total_s\n");
  for (int n : {2, 3, 4}) {
    pnpba::test::RenderedDirectProblem r = pnpba::test::renderedDirectProblem();
    pnpba::DirectBaOptions o;
    o.iterations = 60;
    o.patch_size = n;
    const pnpba::DirectBaSummary s = pnpba::solveDirectBa(r.problem, o);
    double rot = 0, centre = 0;
    for (size_t k = 1; k < r.truth.size(); ++k) {
      const pnpba::SE3Quat& T = r.problem.poses[k].T_cw;
      rot = std::max(rot, (T * r.truth[k].inverse()).log().head<3>().norm() * 180 / M_PI);
      centre =
          std::max(centre, (T.inverse().translation() - r.truth[k].inverse().translation()).norm());
    }
    std::printf("%35dx%d %12.4f %14.2f %8.2f\n", n, n, rot, 1000 * centre, s.time_s);
  }
  return 0;
}

int main(int argc, char** argv) {
  return pnpba::bench::guardedMain("direct_ba_bench", benchMain, argc, argv);
}
