// latency_bench: the two-view pose's in-process time next to its accuracy, per data set, so
// that speed and accuracy are read together. Sets:
//   sweep-rich, sweep-poor, sweep-cabinet  the rendered wide-baseline sweep (every rotation x
//                                          translation cell, --seeds pairs each; exact truth)
//   fr1_desk      the shared TUM fr1_desk pairs (i, i+k), k = 1..8
//   fr1_desk-odometry  its pairs (i, i+1) as an odometry loop runs them: frame i's features are
//                 known from the step before (describeFrame, frame_features.h), and a step is
//                 describing frame i+1 and the estimate given both
//   cabinet       the shared TUM fr3_cabinet key frames, pairs (i, i+1) and (i, i+3)
//                 (2-34 deg, 0.07-0.62 m apart)
//   cabinet-wide  the same key frames, pairs (i, i+5) and (i, i+8): a real texture-poor scene
//                 across wide baselines (26-76 deg, 0.5-1.5 m apart)
//   textbook      the textbook pair (no ground truth: ok = returned), timed 7 times: its times
//                 are the medians
//   --sequence D  a TUM sequence or key-frame folder of the user's (as evaluate_tum reads it):
//                 pairs (i, i+k) for k in --gaps (1,3), i every --every frames; its camera by
//                 evaluate_tum's rule (--camera, D/camera.yaml, the freiburg camera D names)
//   sweep-tiled   (only when asked for) the sweep's cells in the rich room with its texture cut
//                 to a 0.5 m tile and repeated: wrong matches that agree with one another
//   sweep-structure (only when asked for) the sweep's cells around a plain zig-zag of panels
//                 (SceneLayout::kStructure) through the cabinet's sensor: geometry that repeats
//   sweep-corridor (only when asked for) the sweep's cells before a plain wall on a plain floor
//                 (SceneLayout::kCorridor), the cabinet's sensor: a slide along x changes nothing
//   sweep-poster  (only when asked for) the sweep's cells before a rich poster on a plain wall
//                 (SceneLayout::kPoster), the cabinet's sensor: one plane, its colours fix the rest
//   sweep-rich-keyframe, sweep-poor-keyframe, sweep-cabinet-keyframe, sweep-tiled-keyframe
//                 (only when asked for) those scenes' cells' motions from one key frame (each
//                 seed's room as its 0-degree, 0 m cell draws it, frame 1 the same in every
//                 cell), as a relocalisation loop runs them: the key frame described in the set's
//                 first pair, untimed, and kept for the whole set, so that its SIFT retry features
//                 and its depth's description for the registration are made in the first pair
//                 that needs them and taken by the next; a step is describing frame 2 and the
//                 estimate given both
//   In the loops' sets (these and fr1_desk-odometry) every pair is also estimated with nothing
//   given, in turn with the loop's step, and reported beside it as "pnpba-per-pair".
//   unrelated     (only when asked for) frames of two real scenes paired across, both depths:
//                 fr1_desk's frames 0, 2, .., 8 with the cabinet's key frames 0, 5, .., 25, each
//                 way round, under frame 1's camera. No pose relates them (a relocalisation
//                 query of a place not seen): a refusal is the right answer, a returned pose
//                 counts as wrong
// ok: within 2 deg / 5 cm (1 deg / 2 cm on fr1_desk, as its evaluation); wrong: returned but
// more than 10 deg or 50 cm off. A rendered set's pairs are all rendered before its first is
// timed (--render-each: each just before its estimate). Per set: p50 / p95 / max of
// estimateTwoView's total time and the median of every stage over the pairs where it ran. The
// registration's plugin is opened before timing (its one-time load reported apart,
// "plugin_load_ms"), unless --cold. Before the sets and after them, the machine's ORB on one pair
// ("machine", machine_gauge.h): a features stage cannot be faster than that.
// --resize F runs every pair scaled by F first (resized_pair.h): the same scenes as a sensor of
// another resolution sees them; --sensor renders the sweep through another sensor's camera
// (wide_baseline_pairs.h: realsense, azure); --axis turns camera 2 about another axis (tilt,
// roll) than the sweep's own pan.
// Anchors (--anchors), run on every pair after pnpba, in the same run so that a slow or fast
// machine moves both: `opencv`, the careful OpenCV user's ORB + solvePnPRansac + refinement
// (evaluation/opencv_baseline.h, the same feature count), and `open3d`, Open3D's hybrid RGB-D
// odometry from the identity (evaluation/open3d_baseline.h). Neither refuses a pose on evidence: a
// pose they do not return counts as refused, one they return is ok or wrong as pnpba's is.
//
//   build/bench/latency_bench [--json FILE] [--plot FILE.png] [--seeds 1] [--repeats 1]
//                             [--sets sweep,fr1_desk,fr1_desk-odometry,cabinet,cabinet-wide,
//                                     textbook]
//                             [--sequence DIR ... [--gaps 1,3] [--every N] [--camera YAML]]
//                             [--registration ransac|open3d-ransac|fast|candidates]
//                             [--fine-voxel M] [--fpfh-neighbours N] [--max-points N]
//                             [--registration-icp N] [--registration-stride N] [--cold]
//                             [--render-each]
//                             [--resize F] [--sensor tum|realsense|azure|azure-1080p]
//                             [--axis pan|tilt|roll]
//                             [--slide-step M] [--repeat-max-shift M] [--free-slide M]
//                             [--same-coarse-pose DEG] [--converged-step S]
//                             [--conclusive-explained-pairs N]
//                             [--settled-step-sigmas K]
//                             [--anchors opencv,open3d|none]
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <sstream>

#include "bench_output.h"
#include "guarded_main.h"
#include "machine_gauge.h"
#include "percentile.h"
#include "pnpba/core/error.h"
#include "pnpba/core/heap_retention.h"
#include "pnpba/evaluation/evaluation.h"
#include "pnpba/evaluation/open3d_baseline.h"
#include "pnpba/evaluation/opencv_baseline.h"
#include "pnpba/evaluation/tum_cameras.h"
#include "pnpba/evaluation/tum_dataset.h"
#include "pnpba/evaluation/tum_evaluation.h"
#include "pnpba/pipeline/covariance_model.h"
#include "pnpba/pipeline/depth_registration.h"
#include "pnpba/pipeline/image_files.h"
#include "pnpba/pipeline/two_view.h"
#include "resized_pair.h"
#include "wide_baseline_pairs.h"

namespace {

using pnpba::SE3Quat;
using pnpba::bench::percentile;

struct Pair {
  cv::Mat image1, depth1, image2, depth2;
  std::optional<SE3Quat> truth;
  bool unrelated = false;  // frames of two scenes: any returned pose is wrong
  bool odometry = false;   // a loop's step: frame 1's features known, frame 2's found in it
  // A key frame's loop: frame 1's features, described in the set's first pair and kept for the
  // set (what the estimates find for it, the SIFT retry's, with them); frame 2's found in the step.
  std::optional<pnpba::FrameFeatures>* key_frame = nullptr;
};

// Times and answers of one method over a set's pairs.
struct Tally {
  std::vector<double> totals;
  int ok = 0, refused = 0, wrong = 0;
  // Per stage, each pair's median where it ran: pnpba's own rows (the set's, and a loop's
  // pnpba-per-pair), not the anchors of other libraries.
  std::map<std::string, std::vector<double>> stages;
};

struct SetResult {
  explicit SetResult(std::string set_name) : name(std::move(set_name)) {}
  std::string name;
  Tally pnpba;
  std::map<std::string, Tally> anchors;  // by anchor name
  std::string folder, camera;            // a --sequence set's folder and camera's source
  int loop_mismatches = 0;  // a loop's pairs whose answer differs from the pair's own (a fault)
};

bool g_verbose = false;
int g_repeats = 1;  // --repeats: every pair timed this many times, its medians kept
std::vector<std::string> g_anchors = {"opencv", "open3d"};
double g_resize = 1.0;  // --resize: every pair as a sensor of another resolution would see it
constexpr int kTextbookRepeats = 7;
pnpba::TwoViewOptions g_options;

// One line per pair (--verbose): where the time went and what came out (the error against the
// truth, or why it was refused).
void printPair(const SetResult& set, const pnpba::TwoViewResult& r, const Pair& p) {
  const pnpba::StageTimes& t = r.times_ms;
  std::string error = "-";
  if (r.ok && p.truth) {
    const pnpba::PoseError e = pnpba::relativePoseError(r.T_21, *p.truth);
    char text[96];
    const pnpba::PoseSigmas sigma = pnpba::poseSigmas(r.covariance);
    std::snprintf(text, sizeof text, "%.2fdeg/%.1fcm (1-sigma %.2fdeg/%.1fcm)", e.rot_deg,
                  e.trans_cm, sigma.deg, sigma.cm);
    error = text;
  } else if (!r.ok) {
    error = r.failure;  // why it was refused
  }
  // --cold: the pair that opened the registration's plugin waited for it too.
  std::string opening;
  if (t.plugin_load_ms > 0) {
    char load[48];
    std::snprintf(load, sizeof load, " (+ plugin opening %.1f)", t.plugin_load_ms);
    opening = load;
  }
  std::printf(
      "%-13s %3zu %7.1f ms  %-19s %-4s kp %4d %4d pairs %4d | feat %.1f sift %.1f reg %.1f%s "
      "align %.1f (candidates %d, %d again) | consistency %.2f photometric %.2f overlap %.2f | "
      "%s\n",
      set.name.c_str(), set.pnpba.totals.size(), t.total_ms,
      r.ok ? r.path.c_str() : ("x:" + r.failure_rule).c_str(), r.detector.c_str(),
      r.counts.keypoints1, r.counts.keypoints2, r.counts.pairs, t.features_ms, t.sift_retry_ms,
      t.registration_ms, opening.c_str(), t.alignment_ms, r.counts.depth_candidates,
      r.counts.depth_duplicates, r.depth_consistency, r.photometric_agreement, r.overlap,
      error.c_str());
}

// Counts one answer: refused when not returned; else ok within ok_deg / ok_cm (or, without a
// truth, whenever returned) and wrong beyond 10 deg or 50 cm, or at all for unrelated frames.
void tally(bool returned, const SE3Quat& T_21, const Pair& p, double ok_deg, double ok_cm,
           double ms, Tally* t) {
  t->totals.push_back(ms);
  if (!returned) {
    ++t->refused;
    return;
  }
  if (p.unrelated) {
    ++t->wrong;
    return;
  }
  if (!p.truth) {
    ++t->ok;
    return;
  }
  const pnpba::PoseError e = pnpba::relativePoseError(T_21, *p.truth);
  if (e.rot_deg <= ok_deg && e.trans_cm <= ok_cm) ++t->ok;
  if (e.rot_deg > 10.0 || e.trans_cm > 50.0) ++t->wrong;
}

// The anchors on one pair (already resized), each `repeats` times, the median time kept.
void runAnchors(const Pair& p, const pnpba::Camera& camera, double ok_deg, double ok_cm,
                int repeats, SetResult* set) {
  for (const std::string& name : g_anchors) {
    if (name == "open3d" && p.depth2.empty()) continue;  // odometry needs both depths
    bool returned = false;
    SE3Quat T;
    std::vector<double> times;
    for (int k = 0; k < repeats; ++k) {
      if (name == "opencv") {
        pnpba::OpenCvBaselineOptions o;
        o.features = g_options.orb.num_features;
        const pnpba::TwoViewResult r =
            pnpba::estimateTwoViewOpenCv(p.image1, p.depth1, p.image2, camera, o);
        returned = r.ok, T = r.T_21;
        times.push_back(r.times_ms.total_ms);
      } else {
        const pnpba::TwoViewResult r =
            pnpba::estimateTwoViewOpen3dOdometry(p.image1, p.depth1, p.image2, p.depth2, camera);
        returned = r.ok, T = r.T_21;
        times.push_back(r.times_ms.total_ms);
      }
    }
    if (g_verbose) {
      std::string error = "-";
      if (returned && p.truth) {
        const pnpba::PoseError e = pnpba::relativePoseError(T, *p.truth);
        char text[64];
        std::snprintf(text, sizeof text, "%.2fdeg/%.1fcm", e.rot_deg, e.trans_cm);
        error = text;
      }
      std::printf("%-13s %3zu %7.1f ms  anchor %-12s %s\n", set->name.c_str(),
                  set->pnpba.totals.size() - 1, percentile(times, 0.5), name.c_str(),
                  returned ? error.c_str() : "x");
    }
    tally(returned, T, p, ok_deg, ok_cm, percentile(times, 0.5), &set->anchors[name]);
  }
}

// repeats > 1: the pair is estimated that many times and its times are the medians (the
// estimate itself is the same every time); a set of one pair is otherwise one noisy sample.
void run(const Pair& original, const pnpba::Camera& original_camera, double ok_deg, double ok_cm,
         SetResult* set, int repeats = g_repeats) {
  Pair p = original;
  pnpba::Camera camera = original_camera;
  if (g_resize != 1.0) {
    pnpba::bench::resizePair(g_resize, &p.image1, &p.depth1, &p.image2, &p.depth2, &camera);
  }
  pnpba::TwoViewResult r, per_pair;
  std::vector<double> totals, per_pair_totals;
  std::map<std::string, std::vector<double>> stages, per_pair_stages;
  // A loop's step finds frame 1's features in the step before: found here, untimed. A key frame
  // is described once for its set (a copy shares what the estimates keep for it).
  std::optional<pnpba::FrameFeatures> known1;
  if (p.key_frame != nullptr) {
    if (!*p.key_frame) *p.key_frame = pnpba::describeFrame(p.image1, g_options.orb);
    known1 = **p.key_frame;
  } else if (p.odometry) {
    known1 = pnpba::describeFrame(p.image1, g_options.orb);
  }
  // A loop's pair is also estimated as a pair of its own (nothing given), before or after the
  // loop's step in turn, so that both meet the machine in the same state.
  auto perPair = [&] {
    per_pair = pnpba::estimateTwoView(p.image1, p.depth1, p.image2, p.depth2, camera, g_options);
    per_pair_totals.push_back(per_pair.times_ms.total_ms);
    for (const auto& [name, ms] : per_pair.times_ms.named()) {
      if (ms > 0) per_pair_stages[name].push_back(ms);
    }
  };
  for (int k = 0; k < repeats; ++k) {
    if (known1 && k % 2 == 1) perPair();
    if (known1) {
      // The step's whole time: describing frame 2 (its features stage) and the estimate.
      const auto start = std::chrono::steady_clock::now();
      const pnpba::FrameFeatures found2 = pnpba::describeFrame(p.image2, g_options.orb);
      const double describe_ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
              .count();
      r = pnpba::estimateTwoView(p.image1, p.depth1, p.image2, p.depth2, camera, g_options,
                                 &*known1, &found2);
      r.times_ms.features_ms += describe_ms;
      r.times_ms.total_ms += describe_ms;
      if (k % 2 == 0) perPair();
    } else {
      r = pnpba::estimateTwoView(p.image1, p.depth1, p.image2, p.depth2, camera, g_options);
    }
    totals.push_back(r.times_ms.total_ms);
    for (const auto& [name, ms] : r.times_ms.named()) {
      if (ms > 0) stages[name].push_back(ms);
    }
  }
  if (g_verbose) printPair(*set, r, p);
  tally(r.ok, r.T_21, p, ok_deg, ok_cm, percentile(totals, 0.5), &set->pnpba);
  if (known1) {
    // Features given change no answer (frame_features.h): a difference here is a fault.
    if (per_pair.ok != r.ok ||
        per_pair.T_21.to_homogeneous_matrix() != r.T_21.to_homogeneous_matrix()) {
      std::fprintf(stderr,
                   "latency_bench: %s pair %zu: the loop's answer differs from the pair's own\n",
                   set->name.c_str(), set->pnpba.totals.size() - 1);
      ++set->loop_mismatches;
    }
    Tally* own = &set->anchors["pnpba-per-pair"];
    tally(per_pair.ok, per_pair.T_21, p, ok_deg, ok_cm, percentile(per_pair_totals, 0.5), own);
    for (const auto& [name, v] : per_pair_stages) own->stages[name].push_back(percentile(v, 0.5));
  }
  for (const auto& [name, v] : stages) set->pnpba.stages[name].push_back(percentile(v, 0.5));
  runAnchors(p, camera, ok_deg, ok_cm, repeats, set);
}

// Pairs (i, i + k) of a TUM sequence or key-frame folder, for k in `gaps` and i = 0, every,
// 2 every, ..., where both frames have ground truth. A folder that gives none is an error (one
// line naming it), found before any pair is timed.
std::vector<std::pair<int, int>> framePairs(const pnpba::TumSequence& seq,
                                            const std::vector<int>& gaps, int every) {
  std::vector<std::pair<int, int>> pairs;
  const int n = static_cast<int>(seq.frames.size());
  for (int i = 0; i < n; i += every) {
    for (int k : gaps) {
      const int j = i + k;
      if (j < n && seq.ground_truth[i] && seq.ground_truth[j]) pairs.emplace_back(i, j);
    }
  }
  if (pairs.empty()) {
    std::string listed;
    for (int k : gaps) listed += (listed.empty() ? "" : ",") + std::to_string(k);
    throw pnpba::Error(seq.folder + ": no pair (i, i+k) for k in " + listed +
                       " with both frames' ground truth (" + std::to_string(n) + " frames, " +
                       std::to_string(seq.frames_without_ground_truth) + " without ground truth)");
  }
  return pairs;
}

// A set of a sequence's pairs, its files read as the tools read them (a file that is not an
// image is one line naming it).
void tumSet(const std::string& name, const pnpba::TumSequence& seq,
            const std::vector<std::pair<int, int>>& pairs, const pnpba::Camera& camera,
            double ok_deg, double ok_cm, std::vector<SetResult>* out, bool odometry = false) {
  SetResult set(name);
  for (const auto& [i, j] : pairs) {
    const std::string& folder = seq.folder;
    Pair p{pnpba::readColourImage(folder + "/" + seq.frames[i].rgb),
           pnpba::readDepthImage(folder + "/" + seq.frames[i].depth),
           pnpba::readColourImage(folder + "/" + seq.frames[j].rgb),
           pnpba::readDepthImage(folder + "/" + seq.frames[j].depth),
           pnpba::relativePose(*seq.ground_truth[i], *seq.ground_truth[j])};
    p.odometry = odometry;
    run(p, camera, ok_deg, ok_cm, &set);
  }
  out->push_back(std::move(set));
}

// A shared sequence's pairs for the given gaps.
void tumSet(const std::string& name, const std::string& folder, const pnpba::Camera& camera,
            const std::vector<int>& gaps, double ok_deg, double ok_cm, std::vector<SetResult>* out,
            bool odometry = false) {
  const pnpba::TumSequence seq = pnpba::loadTumSequence(folder);
  tumSet(name, seq, framePairs(seq, gaps, 1), camera, ok_deg, ok_cm, out, odometry);
}

// Frames of two scenes paired across, each way round, under frame 1's camera: every 2nd of
// a's frames with every 5th of b's (fr1_desk and the cabinet: 5 x 6 x 2 = 60 pairs).
SetResult unrelatedSet(const std::string& folder_a, const pnpba::Camera& camera_a,
                       const std::string& folder_b, const pnpba::Camera& camera_b) {
  struct Frame {
    cv::Mat colour, depth;
  };
  auto frames = [](const std::string& folder, int every) {
    const pnpba::TumSequence seq = pnpba::loadTumSequence(folder);
    std::vector<Frame> out;
    for (size_t i = 0; i < seq.frames.size(); i += every) {
      out.push_back({pnpba::readColourImage(folder + "/" + seq.frames[i].rgb),
                     pnpba::readDepthImage(folder + "/" + seq.frames[i].depth)});
    }
    return out;
  };
  const std::vector<Frame> a = frames(folder_a, 2), b = frames(folder_b, 5);
  SetResult set("unrelated");
  for (const Frame& x : a) {
    for (const Frame& y : b) {
      Pair ab{x.colour, x.depth, y.colour, y.depth, std::nullopt, true};
      run(ab, camera_a, 0, 0, &set);
      Pair ba{y.colour, y.depth, x.colour, x.depth, std::nullopt, true};
      run(ba, camera_b, 0, 0, &set);
    }
  }
  return set;
}

// A set's name for a user's folder: its last path component ("rgbd_dataset_freiburg2_desk"),
// the path as given when another set has that name already.
std::string sequenceSetName(const std::string& folder, const std::vector<SetResult>& sets) {
  std::string trimmed = folder;
  while (trimmed.size() > 1 && trimmed.back() == '/') trimmed.pop_back();
  const size_t slash = trimmed.find_last_of('/');
  const std::string last = slash == std::string::npos ? trimmed : trimmed.substr(slash + 1);
  const bool taken =
      std::any_of(sets.begin(), sets.end(), [&](const SetResult& s) { return s.name == last; });
  return taken ? trimmed : last;
}

// A CLI11 check that every item of a comma list is one of `allowed`.
CLI::Validator commaListOf(const std::string& what, std::vector<std::string> allowed) {
  return CLI::Validator(
      [what, allowed](const std::string& text) {
        std::stringstream list(text);
        for (std::string item; std::getline(list, item, ',');) {
          if (std::find(allowed.begin(), allowed.end(), item) == allowed.end()) {
            std::string names;
            for (const std::string& a : allowed) names += (names.empty() ? "" : ", ") + a;
            return "unknown " + what + " '" + item + "' (" + names + ")";
          }
        }
        return std::string();
      },
      "");
}

nlohmann::json tallyJson(const Tally& t) {
  return {{"pairs", t.totals.size()},
          {"p50_ms", percentile(t.totals, 0.5)},
          {"p95_ms", percentile(t.totals, 0.95)},
          {"max_ms", percentile(t.totals, 1.0)},
          {"ok", t.ok},
          {"refused", t.refused},
          {"wrong", t.wrong}};
}

void printTally(int name_width, const std::string& name, const Tally& t,
                const std::string& stages) {
  std::printf("%-*s %5zu %8.1f %8.1f %8.1f %4d %7d %5d  %s\n", name_width, name.c_str(),
              t.totals.size(), percentile(t.totals, 0.5), percentile(t.totals, 0.95),
              percentile(t.totals, 1.0), t.ok, t.refused, t.wrong, stages.c_str());
}

// A tick's label in the plot: which method, or the loop's own pairs estimated alone.
const char* anchorLabel(const std::string& name) {
  if (name == "opencv") return "cv";
  if (name == "open3d") return "o3d";
  return "alone";  // pnpba-per-pair
}

void writePlot(const std::string& path, const std::vector<SetResult>& sets) {
  // One row per set: bars for p50, p95 and max on a log time axis (1 ms .. 10 s), with the
  // 33 ms and 100 ms marks.
  const int left = 150, width = 560, row = 34, top = 44;
  cv::Mat canvas(top + row * static_cast<int>(sets.size()) + 40, left + width + 30, CV_8UC3,
                 cv::Scalar::all(255));
  auto x = [&](double ms) {
    return left +
           static_cast<int>(width * std::clamp(std::log10(std::max(ms, 1.0)) / 4.0, 0.0, 1.0));
  };
  const auto font = cv::FONT_HERSHEY_SIMPLEX;
  for (double mark : {1.0, 10.0, 33.0, 100.0, 1000.0, 10000.0}) {
    cv::line(canvas, {x(mark), top - 5}, {x(mark), canvas.rows - 35},
             mark == 33.0 || mark == 100.0 ? cv::Scalar(0, 0, 200) : cv::Scalar::all(210), 1);
    char text[16];
    std::snprintf(text, sizeof text, mark >= 1000 ? "%.0fs" : "%.0fms",
                  mark >= 1000 ? mark / 1000 : mark);
    cv::putText(canvas, text, {x(mark) - 12, canvas.rows - 15}, font, 0.4, cv::Scalar::all(0));
  }
  for (size_t i = 0; i < sets.size(); ++i) {
    const int y = top + static_cast<int>(i) * row;
    cv::putText(canvas, sets[i].name, {8, y + 18}, font, 0.45, cv::Scalar::all(0));
    const std::vector<double>& totals = sets[i].pnpba.totals;
    const double p50 = percentile(totals, 0.5), p95 = percentile(totals, 0.95),
                 max = percentile(totals, 1.0);
    cv::rectangle(canvas, {left, y + 4}, {x(max), y + 24}, cv::Scalar(220, 220, 250), cv::FILLED);
    cv::rectangle(canvas, {left, y + 4}, {x(p95), y + 24}, cv::Scalar(150, 170, 240), cv::FILLED);
    cv::rectangle(canvas, {left, y + 4}, {x(p50), y + 24}, cv::Scalar(60, 120, 220), cv::FILLED);
    // Each anchor's p50: a black tick, labelled by anchorLabel.
    for (const auto& [name, t] : sets[i].anchors) {
      const int ax = x(percentile(t.totals, 0.5));
      cv::line(canvas, {ax, y + 1}, {ax, y + 27}, cv::Scalar::all(0), 2);
      cv::putText(canvas, anchorLabel(name), {ax + 3, y + 28}, font, 0.35, cv::Scalar::all(0));
    }
  }
  cv::putText(canvas, "in-process time per pair: p50 (dark), p95, max (light); red: 33 and 100 ms",
              {8, 16}, font, 0.42, cv::Scalar::all(0));
  cv::putText(canvas,
              "ticks: p50 of OpenCV (cv), Open3D's odometry (o3d), a loop's pairs alone (alone)",
              {8, 34}, font, 0.42, cv::Scalar::all(0));
  pnpba::bench::writePngFile(path, canvas);
}

}  // namespace

// The bench itself (main: guarded_main.h).
static int benchMain(int argc, char** argv) {
  CLI::App app{"Two-view latency next to accuracy, per data set."};
  std::string json_path, plot_path,
      sets_text = "sweep,fr1_desk,fr1_desk-odometry,cabinet,cabinet-wide,textbook";
  int seeds = 1;
  std::string sensor_name = "tum";
  app.add_option("--json", json_path, "write {\"sets\": [...]}");
  app.add_option("--plot", plot_path, "PNG of p50 / p95 / max per set");
  app.add_option("--seeds", seeds, "sweep pairs per cell (the wide-baseline sweep uses 3)")
      ->capture_default_str();
  app.add_flag("--verbose", g_verbose,
               "a line per pair: time, path, stages, and its error or why it was refused");
  app.add_option("--repeats", g_repeats,
                 "time every pair this many times and keep its medians (the machine's noise out of "
                 "p95 and max; the textbook pair at least 7)")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  app.add_option("--sensor", sensor_name, pnpba::bench::kSensorHelp)
      ->check(CLI::IsMember(pnpba::bench::kSensorNames))
      ->capture_default_str();
  std::string axis_name = "pan";
  app.add_option("--axis", axis_name, pnpba::bench::kSweepAxisHelp)
      ->check(CLI::IsMember(pnpba::bench::kSweepAxisNames))
      ->capture_default_str();
  app.add_option("--resize", g_resize,
                 "scale every image (and the intrinsics) by this factor first: the same pairs "
                 "as a sensor of another resolution sees them")
      ->check(CLI::Range(0.25, 4.0))
      ->capture_default_str();
  std::string method = pnpba::toString(g_options.registration.method);
  app.add_option("--registration", method,
                 "the depth path's global registration: ransac, open3d-ransac, fast "
                 "or candidates")
      ->check(CLI::IsMember({"ransac", "open3d-ransac", "fast", "candidates"}));
  app.add_option("--voxel", g_options.registration.voxel_m, "the registration's voxel ceiling (m)");
  app.add_option("--voxel-depth-fraction", g_options.registration.voxel_depth_fraction,
                 "the registration's voxel as this fraction of depth 1's median, where smaller "
                 "(0: the ceiling always)");
  app.add_option("--fine-voxel", g_options.registration.fine_voxel_m,
                 "the registration's last ICP voxel (m; 0: none)");
  app.add_option("--fpfh-neighbours", g_options.registration.fpfh_neighbours,
                 "the registration's FPFH neighbours at most");
  app.add_option("--max-points", g_options.registration.max_points,
                 "the registration's cloud 1 at most about this many points (0: no limit)");
  app.add_option("--registration-icp", g_options.registration.icp_iterations,
                 "the registration's ICP iterations per stage (0: none)");
  app.add_option("--max-candidates", g_options.registration.candidates.max_candidates,
                 "the candidates search's distinct poses at most");
  app.add_option("--aligned-candidates", g_options.aligned_registration_candidates,
                 "registration candidates aligned in full at most (0: all)");
  app.add_option("--registration-stride", g_options.registration.pixel_stride,
                 "the registration back-projects every n-th pixel");
  app.add_option("--slide-step", g_options.slide_search.step_m,
                 "the depth path's slide search step (m; 0: no search)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--repeat-max-shift", g_options.repeat_search.max_shift_m,
                 "the depth path's search for a twin along a repeat, up to this shift (m; 0: no "
                 "search)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--free-slide", g_options.repeat_search.free_slide_m,
                 "the repeat search also takes a slide the depths leave free this far as a twin "
                 "(m; 0: no free slides)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--converged-step", g_options.rgbd_alignment.converged_step,
                 "the RGB-D alignment ends a level at steps below this (rad and m)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_option("--settled-step-sigmas", g_options.rgbd_alignment.settled_step_sigmas,
                 "the RGB-D alignment ends its full-resolution level, from the third step on, at "
                 "a step within this many of the pose's standard deviations (0: off)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--brightness-gain-sigma", g_options.rgbd_alignment.brightness_gain_sigma,
                 "the depth path fits frame 2's brightness as a gain and an offset of frame 1's, "
                 "the gain with this prior 1-sigma (0: the offset alone)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--same-coarse-pose", g_options.same_coarse_pose_deg,
                 "a depth-path candidate whose coarse levels end within this angle (deg) of an "
                 "earlier one's is that one again (0: every candidate aligned in full)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--conclusive-explained-pairs", g_options.conclusive_min_explained_pairs,
                 "an aligned feature pose the depths and colours back is conclusive with this many "
                 "feature pairs explained where no rival RANSAC pose comes near (0: half the pairs "
                 "always)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--max-feature-pixels", g_options.orb.max_pixels,
                 "ORB on a copy of an image of more pixels than this, shrunk by the smallest "
                 "whole factor that brings it within (0: every image at its own resolution)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--time-budget-ms", g_options.time_budget_ms,
                 "each estimate's time budget: an optional stage that would not fit refuses the "
                 "pair as time_budget (0: none)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--sets", sets_text,
                 "comma list: sweep, fr1_desk, fr1_desk-odometry (its pairs (i, i+1) as an "
                 "odometry loop runs them, each frame's features found once), cabinet, "
                 "cabinet-wide, textbook; also "
                 "sweep-tiled (the sweep's cells in the rich room with its texture tiled) and "
                 "sweep-structure (around a plain zig-zag of panels), sweep-corridor (a plain "
                 "wall on a plain floor) and sweep-poster (a rich poster on a plain wall); "
                 "sweep-rich-keyframe, sweep-poor-keyframe, sweep-cabinet-keyframe and "
                 "sweep-tiled-keyframe (those cells as a relocalisation loop against their "
                 "shared frame 1 runs them: its features, the SIFT retry's and its depth's "
                 "description for the registration too, found once); unrelated (fr1_desk's frames "
                 "paired with the cabinet's: every "
                 "answer should be a refusal)")
      ->check(
          commaListOf("set", {"sweep", "fr1_desk", "fr1_desk-odometry", "cabinet", "cabinet-wide",
                              "textbook", "sweep-tiled", "sweep-structure", "sweep-corridor",
                              "sweep-poster", "sweep-rich-keyframe", "sweep-poor-keyframe",
                              "sweep-cabinet-keyframe", "sweep-tiled-keyframe", "unrelated"}))
      ->capture_default_str();
  std::vector<std::string> sequences;
  CLI::Option* sequence_option = app.add_option(
      "--sequence", sequences,
      "a TUM RGB-D sequence folder or key-frame folder of your own, as evaluate_tum "
      "reads it (repeatable): its pairs (i, i+k), a set named by the folder, ok within "
      "2 deg / 5 cm; alone, only these sets run unless --sets names others");
  std::vector<int> gaps = {1, 3};
  app.add_option("--gaps", gaps, "--sequence: pairs (i, i+k) for these k")
      ->needs(sequence_option)
      ->delimiter(',')
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  int every = 1;
  app.add_option("--every", every,
                 "--sequence: first frames i = 0, N, 2N, ... (a 30 Hz sequence's thousands of "
                 "frames in fewer pairs)")
      ->needs(sequence_option)
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  std::string camera_path;
  app.add_option("--camera", camera_path,
                 "--sequence: camera YAML (default: FOLDER/camera.yaml, else the TUM freiburg "
                 "camera the folder's name says, else freiburg1)")
      ->needs(sequence_option);
  std::string anchors_text = "opencv,open3d";
  app.add_option("--anchors", anchors_text,
                 "comma list of methods run on every pair beside pnpba, in the same run: opencv "
                 "(ORB + solvePnPRansac), open3d (Open3D's RGB-D odometry), or none")
      ->check(commaListOf("anchor", {"opencv", "open3d", "none"}))
      ->capture_default_str();
  bool cold = false;
  bool render_each = false;
  app.add_flag("--render-each", render_each,
               "render each sweep pair just before its estimate rather than a set's pairs before "
               "the first (the renderer's work between estimates then slows the next one)");
  app.add_flag("--cold", cold,
               "open the registration's plugin in the first pair that needs it (its one-time "
               "load then counts in that pair) instead of before timing");
  CLI11_PARSE(app, argc, argv);
  pnpba::bench::checkOutputPaths({json_path, plot_path});
  if (!sequences.empty() && app.count("--sets") == 0) sets_text.clear();
  // Every folder and its camera are checked before the first pair is timed: a typo in the
  // second costs no run of the first.
  std::vector<pnpba::TumSequence> sequence_frames;
  std::vector<std::vector<std::pair<int, int>>> sequence_pairs;
  std::vector<pnpba::SequenceCamera> sequence_cameras;
  for (const std::string& folder : sequences) {
    sequence_frames.push_back(pnpba::loadTumSequence(folder));
    sequence_pairs.push_back(framePairs(sequence_frames.back(), gaps, every));
    sequence_cameras.push_back(pnpba::sequenceCamera(folder, camera_path));
  }
  // The evidence takes the brightness change out as the alignment does.
  g_options.alignment_evidence.brightness_gain_sigma =
      g_options.rgbd_alignment.brightness_gain_sigma;
  g_options.registration.method = pnpba::parseGlobalRegistration(method);
  g_anchors.clear();
  {
    std::stringstream list(anchors_text);
    for (std::string a; std::getline(list, a, ',');) {
      // Open3D's odometry would load Open3D before the registration's first use, which --cold
      // is there to time.
      if (a == "open3d" && cold) {
        std::fprintf(stderr, "latency_bench: --cold runs without the open3d anchor\n");
      } else if (a != "none") {
        g_anchors.push_back(a);
      }
    }
  }
  // A loop pays the plugin's load once; timed in a pair it would be that pair's largest stage.
  double plugin_load_ms = -1;
  if (!cold) {
    try {
      plugin_load_ms = pnpba::preloadDepthRegistration();
    } catch (const std::exception& e) {
      std::fprintf(stderr, "latency_bench: %s\n", e.what());
      return 2;
    }
    std::fprintf(stderr, "latency_bench: registration plugin opened in %.1f ms, before timing\n",
                 plugin_load_ms);
  }
  auto wanted = [&](const std::string& s) {
    return ("," + sets_text + ",").find("," + s + ",") != std::string::npos;
  };
  const std::string shared = PNPBA_SHARED_DATA;
  // The heap as the first estimate leaves it (heap_retention.h), so that the gauges below see the
  // allocator the estimates see.
  pnpba::retainFreedHeapMemoryOnce();
  // The machine's ORB on the textbook pair's images, before the sets and after them (its state
  // can change within a run).
  const cv::Mat gauge1 = cv::imread(shared + "/slambook_ch7/1.png");
  const cv::Mat gauge2 = cv::imread(shared + "/slambook_ch7/2.png");
  auto gauge = [&](const char* when) {
    if (gauge1.empty() || gauge2.empty()) return nlohmann::json();
    const pnpba::bench::MachineGauge g = pnpba::bench::gaugeOrb(gauge1, gauge2, g_options.orb);
    std::fprintf(stderr,
                 "latency_bench: this machine's ORB on a 640 x 480 pair %s: %.1f ms one image "
                 "after the other, %.1f ms side by side\n",
                 when, g.one_after_the_other_ms, g.side_by_side_ms);
    return nlohmann::json{{"orb_pair_one_thread_ms", g.one_after_the_other_ms},
                          {"orb_pair_two_threads_ms", g.side_by_side_ms}};
  };
  nlohmann::json machine = {{"before", gauge("before timing")}};
  std::vector<SetResult> sets;
  using pnpba::bench::SweepScene;
  // A sweep set: a scene's cells, each pair on its own or as a key frame's loop runs it.
  struct SweepSet {
    SweepScene scene;
    bool key_frame = false;
  };
  std::vector<SweepSet> sweep_sets;
  if (wanted("sweep")) {
    sweep_sets = {{SweepScene::kRich}, {SweepScene::kPoor}, {SweepScene::kCabinet}};
  }
  if (wanted("sweep-tiled")) sweep_sets.push_back({SweepScene::kTiled});
  if (wanted("sweep-structure")) sweep_sets.push_back({SweepScene::kStructure});
  if (wanted("sweep-corridor")) sweep_sets.push_back({SweepScene::kCorridor});
  if (wanted("sweep-poster")) sweep_sets.push_back({SweepScene::kPoster});
  if (wanted("sweep-rich-keyframe")) sweep_sets.push_back({SweepScene::kRich, true});
  if (wanted("sweep-poor-keyframe")) sweep_sets.push_back({SweepScene::kPoor, true});
  if (wanted("sweep-cabinet-keyframe")) sweep_sets.push_back({SweepScene::kCabinet, true});
  if (wanted("sweep-tiled-keyframe")) sweep_sets.push_back({SweepScene::kTiled, true});
  if (!sweep_sets.empty()) {
    const pnpba::SyntheticCamera sensor = pnpba::bench::sensorCamera(sensor_name);
    const pnpba::Camera camera = pnpba::bench::estimationCamera(sensor);
    for (const auto& [scene, key_frame] : sweep_sets) {
      SetResult set(std::string("sweep-") + pnpba::bench::toString(scene) +
                    (key_frame ? "-keyframe" : ""));
      // Each seed's key frame (its cells' shared frame 1), described in its first pair.
      std::map<int, std::optional<pnpba::FrameFeatures>> key_frames;
      // A set's pairs are rendered before the first is timed, as the TUM sets' frames are read:
      // rendering between two estimates (tens of ms on both cores, over memory of its own)
      // slowed the next estimate by a third to a half (docs/benchmarks.md), which no loop over
      // pairs in memory or on disk meets. --render-each renders each just before its estimate.
      std::vector<Pair> rendered;
      for (double deg : {0.0, 10.0, 20.0, 30.0, 45.0, 60.0}) {
        for (double metres : {0.0, 0.25, 0.5, 1.0, 1.5, 2.0}) {
          for (int s = 0; s < seeds; ++s) {
            const pnpba::bench::SweepAxis axis = pnpba::bench::parseSweepAxis(axis_name);
            pnpba::SyntheticPairOptions o =
                pnpba::bench::wideBaselinePair(scene, deg, metres, s, axis);
            // A key frame's cells: the cell's motion in the room of the seed's first cell.
            if (key_frame) o.seed = pnpba::bench::wideBaselinePair(scene, 0.0, 0.0, s, axis).seed;
            o.camera = sensor;
            const pnpba::SyntheticPair sp = pnpba::renderSyntheticPair(o);
            if (!pnpba::bench::bothViewsHaveDepth(sp)) {
              std::fprintf(stderr,
                           "latency_bench: %s %.0f deg %.2f m seed %d: a view without depth (the "
                           "camera turned away from the scene): left out\n",
                           set.name.c_str(), deg, metres, s);
              continue;
            }
            Pair pair{sp.view1.colour, sp.view1.depth, sp.view2.colour, sp.view2.depth, sp.T_21};
            if (key_frame) pair.key_frame = &key_frames[s];
            if (render_each) {
              run(pair, camera, 2.0, 5.0, &set);
            } else {
              rendered.push_back(std::move(pair));
            }
          }
        }
      }
      for (const Pair& pair : rendered) run(pair, camera, 2.0, 5.0, &set);
      sets.push_back(std::move(set));
      std::fprintf(stderr, "latency_bench: %s done\n", sets.back().name.c_str());
    }
  }
  if (wanted("fr1_desk")) {
    tumSet("fr1_desk", shared + "/tum_fr1_desk", pnpba::tumFreiburg1Camera(),
           {1, 2, 3, 4, 5, 6, 7, 8}, 1.0, 2.0, &sets);
  }
  if (wanted("fr1_desk-odometry")) {
    tumSet("fr1_desk-odometry", shared + "/tum_fr1_desk", pnpba::tumFreiburg1Camera(), {1}, 1.0,
           2.0, &sets, /*odometry=*/true);
  }
  const auto fr3 = [] {
    return pnpba::loadCameraYaml(std::string(PNPBA_SOURCE_DIR) + "/data/cameras/tum_fr3.yaml");
  };
  if (wanted("cabinet")) {
    tumSet("cabinet", shared + "/tum_fr3_cabinet_keyframes", fr3(), {1, 3}, 2.0, 5.0, &sets);
  }
  if (wanted("cabinet-wide")) {
    tumSet("cabinet-wide", shared + "/tum_fr3_cabinet_keyframes", fr3(), {5, 8}, 2.0, 5.0, &sets);
  }
  if (wanted("unrelated")) {
    sets.push_back(unrelatedSet(shared + "/tum_fr1_desk", pnpba::tumFreiburg1Camera(),
                                shared + "/tum_fr3_cabinet_keyframes", fr3()));
  }
  for (size_t k = 0; k < sequences.size(); ++k) {
    const pnpba::SequenceCamera& c = sequence_cameras[k];
    std::fprintf(stderr, "latency_bench: %s: camera %s, %zu pairs\n", sequences[k].c_str(),
                 c.source.c_str(), sequence_pairs[k].size());
    tumSet(sequenceSetName(sequences[k], sets), sequence_frames[k], sequence_pairs[k], c.camera,
           2.0, 5.0, &sets);
    sets.back().folder = sequences[k];
    sets.back().camera = c.source;
  }
  if (wanted("textbook")) {
    const std::string d = shared + "/slambook_ch7/";
    SetResult set("textbook");
    run({cv::imread(d + "1.png"),
         cv::imread(d + "1_depth.png", cv::IMREAD_UNCHANGED),
         cv::imread(d + "2.png"),
         cv::imread(d + "2_depth.png", cv::IMREAD_UNCHANGED),
         {}},
        pnpba::Camera{}, 0, 0, &set, std::max(kTextbookRepeats, g_repeats));
    sets.push_back(std::move(set));
  }

  machine["after"] = gauge("after timing");
  nlohmann::json out = nlohmann::json::array();
  // A user's folder can name a set longer than the shared sets' 14 columns, and an anchor's row
  // ("  vs NAME") can be longer than its set's name.
  const std::string kAnchorPrefix = "  vs ";
  int name_width = 14;
  for (const SetResult& s : sets) {
    name_width = std::max(name_width, static_cast<int>(s.name.size()));
    for (const auto& anchor : s.anchors) {
      name_width =
          std::max(name_width, static_cast<int>(kAnchorPrefix.size() + anchor.first.size()));
    }
  }
  std::printf("%-*s %5s %8s %8s %8s %4s %7s %5s   stage medians (ms, where run)\n", name_width,
              "set", "pairs", "p50_ms", "p95_ms", "max_ms", "ok", "refused", "wrong");
  // A row: printed with its stages' medians, and its JSON with each stage's median in
  // milliseconds, as every *_ms field holds, and apart from it the number of pairs it ran in (the
  // median is over those); an anchor of another library has no stages.
  auto row = [&](const std::string& name, const Tally& t) {
    nlohmann::json stages = nlohmann::json::object(), ran = nlohmann::json::object();
    std::string stage_text;
    for (const auto& [stage, v] : t.stages) {
      stages[stage] = percentile(v, 0.5);
      ran[stage] = v.size();
      char text[96];
      std::snprintf(text, sizeof text, " %s %.1f (%zu)", stage.c_str(), percentile(v, 0.5),
                    v.size());
      stage_text += text;
    }
    printTally(name_width, name, t, stage_text);
    nlohmann::json j = tallyJson(t);
    if (!t.stages.empty()) j["stages_ms"] = stages, j["stages_ran"] = ran;
    return j;
  };
  for (const SetResult& s : sets) {
    nlohmann::json set = row(s.name, s.pnpba);
    set["name"] = s.name;
    if (!s.folder.empty()) set["folder"] = s.folder, set["camera"] = s.camera;
    // Every set has them, a set whose pairs all failed to run a stage too.
    if (!set.contains("stages_ms")) {
      set["stages_ms"] = nlohmann::json::object(), set["stages_ran"] = nlohmann::json::object();
    }
    nlohmann::json anchors = nlohmann::json::array();
    for (const auto& [name, t] : s.anchors) {
      nlohmann::json a = row(kAnchorPrefix + name, t);
      a["name"] = name;
      anchors.push_back(a);
    }
    set["anchors"] = anchors;
    out.push_back(set);
  }
  if (!plot_path.empty()) writePlot(plot_path, sets);
  if (!json_path.empty()) {
    nlohmann::json doc{{"sets", out}};
    if (plugin_load_ms >= 0) doc["plugin_load_ms"] = plugin_load_ms;
    if (!machine["before"].is_null()) doc["machine"] = machine;
    pnpba::bench::writeJsonFile(json_path, doc, 1);
  }
  for (const SetResult& s : sets) {
    if (s.loop_mismatches > 0) {
      std::fprintf(stderr, "latency_bench: %s: %d pairs answered differently in the loop\n",
                   s.name.c_str(), s.loop_mismatches);
      return 1;
    }
  }
  return 0;
}

int main(int argc, char** argv) {
  return pnpba::bench::guardedMain("latency_bench", benchMain, argc, argv);
}
