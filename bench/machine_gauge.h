// How fast this machine runs the floor of a feature-settled pair: OpenCV's ORB, with the
// pipeline's options, on the two images of one pair, one image after the other on one thread
// (an arena of one thread, as ORB's levels would otherwise spread over both cores) and side by
// side on both cores (detectOrbPair, as the features stage runs it). The same 2-core
// machine kind reads 4-5 ms an image in one state and nearly twice that in another, and in the
// slow one the second core adds little (docs/benchmarks.md, "What the machine's states are"):
// latency_bench reports this beside its sets, so that a p50 is read against the machine it ran on.
#pragma once

#include <oneapi/tbb/task_arena.h>

#include <chrono>
#include <opencv2/core.hpp>
#include <vector>

#include "percentile.h"
#include "pnpba/features/orb_features.h"

namespace pnpba::bench {

struct MachineGauge {
  double one_after_the_other_ms = 0;  // both images on one thread
  double side_by_side_ms = 0;         // both images on both cores
};

// Medians of `repeats` runs of each, alternated.
inline MachineGauge gaugeOrb(const cv::Mat& image1, const cv::Mat& image2,
                             const OrbOptions& options, int repeats = 15) {
  using Clock = std::chrono::steady_clock;
  auto msSince = [](Clock::time_point t) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
  };
  std::vector<double> serial, parallel;
  tbb::task_arena one_thread(1);
  for (int i = 0; i < repeats; ++i) {
    auto t = Clock::now();
    one_thread.execute([&] {
      detectOrb(image1, options);
      detectOrb(image2, options);
    });
    serial.push_back(msSince(t));
    t = Clock::now();
    detectOrbPair(image1, image2, options);
    parallel.push_back(msSince(t));
  }
  return {percentile(serial, 0.5), percentile(parallel, 0.5)};
}

}  // namespace pnpba::bench
