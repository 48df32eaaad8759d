// pipeline_bench: the two-view pipeline on the textbook pair (shared/data/slambook_ch7), end
// to end and per stage, side by side with an OpenCV-only re-implementation of the textbook
// program's pipeline (ORB 500, BF Hamming, max(2 min, 30) filter, depth lookup,
// solvePnP ITERATIVE). The textbook's g2o BA is not packaged here: its time comes from the
// reference README (227-231 us, verbose off), to be added to BM_TextbookOpenCV.
//
//   build/bench/pipeline_bench --benchmark_repetitions=10 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>
#include <oneapi/tbb/parallel_invoke.h>

#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "pnpba/features/matching.h"
#include "pnpba/features/orb_features.h"
#include "pnpba/pipeline/depth_consistency.h"
#include "pnpba/pipeline/rgbd_alignment.h"
#include "pnpba/pipeline/two_view.h"

namespace pnpba {
namespace {

struct Pair {
  cv::Mat image1, image2, depth1, depth2;
};

const Pair& textbookPair() {
  static const Pair p = [] {
    const std::string d = std::string(PNPBA_SHARED_DATA) + "/slambook_ch7/";
    return Pair{cv::imread(d + "1.png", cv::IMREAD_COLOR),
                cv::imread(d + "2.png", cv::IMREAD_COLOR),
                cv::imread(d + "1_depth.png", cv::IMREAD_UNCHANGED),
                cv::imread(d + "2_depth.png", cv::IMREAD_UNCHANGED)};
  }();
  return p;
}

// The textbook program's front end and PnP, written with OpenCV alone.
void BM_TextbookOpenCV(benchmark::State& state) {
  const Pair& p = textbookPair();
  const cv::Mat K = (cv::Mat_<double>(3, 3) << 520.9, 0, 325.1, 0, 521.0, 249.7, 0, 0, 1);
  size_t pairs = 0;
  for (auto _ : state) {
    std::vector<cv::KeyPoint> k1, k2;
    cv::Mat d1, d2;
    cv::Ptr<cv::ORB> orb = cv::ORB::create();
    orb->detect(p.image1, k1);
    orb->detect(p.image2, k2);
    orb->compute(p.image1, k1, d1);
    orb->compute(p.image2, k2, d2);
    std::vector<cv::DMatch> all, good;
    cv::BFMatcher(cv::NORM_HAMMING).match(d1, d2, all);
    double min_dist = 10000;
    for (const auto& m : all) min_dist = std::min<double>(min_dist, m.distance);
    for (const auto& m : all)
      if (m.distance <= std::max(2 * min_dist, 30.0)) good.push_back(m);
    std::vector<cv::Point3f> p3;
    std::vector<cv::Point2f> p2;
    for (const auto& m : good) {
      const cv::Point2f& kp = k1[m.queryIdx].pt;
      const uint16_t d = p.depth1.at<uint16_t>(int(kp.y), int(kp.x));
      if (d == 0) continue;
      const float z = d / 5000.0f;
      p3.emplace_back((kp.x - 325.1) / 520.9 * z, (kp.y - 249.7) / 521.0 * z, z);
      p2.push_back(k2[m.trainIdx].pt);
    }
    cv::Mat r, t;
    cv::solvePnP(p3, p2, K, cv::Mat(), r, t, false);
    benchmark::DoNotOptimize(t);
    pairs = p3.size();
  }
  state.counters["pairs"] = pairs;
}
BENCHMARK(BM_TextbookOpenCV)->Unit(benchmark::kMicrosecond);

void runPnpba(benchmark::State& state, const TwoViewOptions& options, bool with_depth2) {
  const Pair& p = textbookPair();
  StageTimes sum;
  int n = 0;
  TwoViewResult r;
  for (auto _ : state) {
    r = estimateTwoView(p.image1, p.depth1, p.image2, with_depth2 ? p.depth2 : cv::Mat(), Camera{},
                        options);
    sum.features_ms += r.times_ms.features_ms;
    sum.matching_ms += r.times_ms.matching_ms;
    sum.depth_ms += r.times_ms.depth_ms;
    sum.pnp_ms += r.times_ms.pnp_ms;
    sum.ba_ms += r.times_ms.ba_ms;
    ++n;
  }
  // Mean stage times (us) of the timed iterations.
  state.counters["orb_us"] = 1000 * sum.features_ms / n;
  state.counters["match_us"] = 1000 * sum.matching_ms / n;
  state.counters["depth_us"] = 1000 * sum.depth_ms / n;
  state.counters["pnp_us"] = 1000 * sum.pnp_ms / n;
  state.counters["ba_us"] = 1000 * sum.ba_ms / n;
  state.counters["inliers"] = r.counts.inliers;
}

// Equal feature count with the textbook (500): its preset (iterative PnP + textbook BA) ...
void BM_PnpbaTextbookPreset(benchmark::State& state) {
  runPnpba(state, TwoViewOptions::textbookPreset(), false);
}
BENCHMARK(BM_PnpbaTextbookPreset)->Unit(benchmark::kMicrosecond);

// ... and the default pipeline (ratio test, EPnP RANSAC, rgbd BA with depth 2) at 500 ...
void BM_PnpbaDefault500(benchmark::State& state) {
  TwoViewOptions o;
  o.orb.num_features = 500;
  runPnpba(state, o, true);
}
BENCHMARK(BM_PnpbaDefault500)->Unit(benchmark::kMicrosecond);

// ... and at its default 1000 features.
void BM_PnpbaDefault(benchmark::State& state) { runPnpba(state, TwoViewOptions{}, true); }
BENCHMARK(BM_PnpbaDefault)->Unit(benchmark::kMicrosecond);

// Matching alone: the textbook pair's 1500 descriptors per image, each one's two nearest (on both
// cores), then the ratio test: the default pipeline's matching (ORB) and the wide-baseline
// retry's (SIFT), through each kernel (argument: MatchKernel; one the CPU lacks is skipped; for
// SIFT kScalar is OpenCV's BFMatcher) and, as the anchor for ORB, BFMatcher's knnMatch with the
// same ratio test.
void matchingBenchmark(benchmark::State& state, Detector detector) {
  const auto kernel = static_cast<MatchKernel>(state.range(0));
  if (!hasMatchKernel(kernel)) {
    state.SkipWithError("this CPU lacks the kernel");
    return;
  }
  const Pair& p = textbookPair();
  OrbOptions options;
  options.detector = detector;
  options.num_features = 1500;
  const auto [f1, f2] = detectOrbPair(p.image1, p.image2, options);
  size_t matches = 0;
  for (auto _ : state) {
    matches = matchDescriptors(f1.descriptors, f2.descriptors, MatchOptions{}, kernel).size();
    benchmark::DoNotOptimize(matches);
  }
  state.counters["matches"] = matches;
  state.counters["descriptors"] = f1.descriptors.rows;
}
void BM_OrbMatching(benchmark::State& state) { matchingBenchmark(state, Detector::kOrb); }
void BM_SiftMatching(benchmark::State& state) { matchingBenchmark(state, Detector::kSift); }
BENCHMARK(BM_OrbMatching)
    ->ArgName("kernel_fastest_avx512_avx2_scalar")
    ->DenseRange(0, 3)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_SiftMatching)
    ->ArgName("kernel_fastest_avx512_avx2_scalar")
    ->DenseRange(0, 3)
    ->Unit(benchmark::kMicrosecond);

// SIFT's features on the textbook pair, the two images side by side: pnpba's detectOrbPair
// (OpenCV detects, the descriptors by pnpba's kernel where the CPU has AVX2), and as the anchor
// OpenCV's detectAndCompute on the image detectOrb gives SIFT, side by side the same way.
// Argument 0: the SIFT retry's options (as siftRetryOptions sets them at 640 x 480: 3000
// features, half OpenCV's contrast threshold, the scale space from 0.85 of the image); 1:
// `--detector sift`'s (1500 features, the image doubled as OpenCV does).
OrbOptions siftFeatures(int which) {
  OrbOptions o;
  o.detector = Detector::kSift;
  o.num_features = 1500;
  if (which == 0) {
    o.num_features = 3000;
    o.sift_first_octave = 0;
    o.sift_octave_fraction = 0.85;
    o.sift_contrast_threshold = 0.02;
  }
  return o;
}
void BM_SiftFeatures(benchmark::State& state) {
  const Pair& p = textbookPair();
  const OrbOptions o = siftFeatures(static_cast<int>(state.range(0)));
  size_t keypoints = 0;
  for (auto _ : state) {
    const auto [f1, f2] = detectOrbPair(p.image1, p.image2, o);
    keypoints = f1.keypoints.size() + f2.keypoints.size();
    benchmark::DoNotOptimize(keypoints);
  }
  state.counters["keypoints"] = keypoints;
}
void BM_SiftFeaturesOpenCv(benchmark::State& state) {
  const Pair& p = textbookPair();
  const OrbOptions o = siftFeatures(static_cast<int>(state.range(0)));
  auto input = [&o](const cv::Mat& image) {
    if (o.sift_first_octave < 0) return image;
    const double by = 2 / o.sift_octave_fraction;  // detectSift's shrink, first octave 0
    cv::Mat small;
    cv::resize(image, small, cv::Size(std::lround(image.cols / by), std::lround(image.rows / by)),
               0, 0, cv::INTER_AREA);
    return small;
  };
  size_t keypoints = 0;
  for (auto _ : state) {
    std::vector<cv::KeyPoint> k1, k2;
    cv::Mat d1, d2;
    const auto sift = cv::SIFT::create(o.num_features, 3, o.sift_contrast_threshold);
    tbb::parallel_invoke([&] { sift->detectAndCompute(input(p.image1), cv::noArray(), k1, d1); },
                         [&] { sift->detectAndCompute(input(p.image2), cv::noArray(), k2, d2); });
    keypoints = k1.size() + k2.size();
    benchmark::DoNotOptimize(keypoints);
  }
  state.counters["keypoints"] = keypoints;
}
BENCHMARK(BM_SiftFeatures)
    ->ArgName("retry0_detector1")
    ->DenseRange(0, 1)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_SiftFeaturesOpenCv)
    ->ArgName("retry0_detector1")
    ->DenseRange(0, 1)
    ->Unit(benchmark::kMicrosecond);

void BM_OrbMatchingBfMatcher(benchmark::State& state) {
  const Pair& p = textbookPair();
  OrbOptions orb;
  orb.num_features = 1500;
  const auto [f1, f2] = detectOrbPair(p.image1, p.image2, orb);
  size_t matches = 0;
  for (auto _ : state) {
    std::vector<std::vector<cv::DMatch>> knn;
    cv::BFMatcher(cv::NORM_HAMMING).knnMatch(f1.descriptors, f2.descriptors, knn, 2);
    matches = 0;
    for (const auto& pair : knn) {
      matches += pair.size() == 2 && pair[0].distance < 0.8 * pair[1].distance;
    }
    benchmark::DoNotOptimize(matches);
  }
  state.counters["matches"] = matches;
}
BENCHMARK(BM_OrbMatchingBfMatcher)->Unit(benchmark::kMicrosecond);

// The depth path's RGB-D alignment alone (pyramid included), from the identity to the textbook
// pair's motion: every level, 640 x 480 at its finest.
void BM_RgbdAlignment(benchmark::State& state) {
  const Pair& p = textbookPair();
  const Camera camera;
  RgbdAlignment a;
  for (auto _ : state) {
    a = alignRgbd(p.image1, p.depth1, p.image2, p.depth2, camera.pinhole, camera.depth_scale,
                  SE3Quat(), {}, RgbdAlignmentOptions{});
    benchmark::DoNotOptimize(a.T_21);
  }
  state.counters["iterations"] = a.iterations;
  state.counters["ok"] = a.ok;
}
BENCHMARK(BM_RgbdAlignment)->Unit(benchmark::kMicrosecond);

// The depths' consistency with one pose (both directions, every n-th pixel), which the depth
// path measures dozens of times a pair: every 8th pixel for its slide search and slide sigmas,
// every 32nd for the repeat search's shifted poses. The textbook pair at a pose near its motion.
void BM_DepthConsistency(benchmark::State& state) {
  const Pair& p = textbookPair();
  const Camera camera;
  const SE3Quat T(Eigen::Quaterniond(Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitY())),
                  Eigen::Vector3d(-0.1, 0.02, 0.05));
  DepthConsistency c;
  for (auto _ : state) {
    c = measureDepthConsistency(p.depth1, p.depth2, T, camera.pinhole, camera.depth_scale,
                                static_cast<int>(state.range(0)));
    benchmark::DoNotOptimize(c.agree);
  }
  state.counters["checked"] = c.checked;
}
BENCHMARK(BM_DepthConsistency)->Arg(8)->Arg(32)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace pnpba

BENCHMARK_MAIN();
