#include "pnpba/evaluation/tum_evaluation.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>  // the flags; the codecs come through pnpba::imageio
#include <sstream>

#include "pnpba/core/error.h"
#include "pnpba/evaluation/open3d_baseline.h"
#include "pnpba/evaluation/opencv_baseline.h"
#include "pnpba/imageio/image_codec.h"
#include "pnpba/pipeline/covariance_model.h"
#include "pnpba/pipeline/depth_registration.h"
#include "pnpba/pipeline/two_view.h"

namespace pnpba {

namespace {

struct Frame {
  cv::Mat colour, depth;
};

// Frames of the pairs still to come, loaded once each.
class FrameCache {
 public:
  FrameCache(const std::string& folder, const TumSequence& sequence)
      : folder_(folder), sequence_(sequence) {}

  const Frame& get(int i) {
    auto it = frames_.find(i);
    if (it != frames_.end()) return it->second;
    const std::string rgb = folder_ + "/" + sequence_.frames[i].rgb;
    const std::string depth = folder_ + "/" + sequence_.frames[i].depth;
    Frame f{pnpba::loadImage(rgb, cv::IMREAD_COLOR), pnpba::loadImage(depth, cv::IMREAD_UNCHANGED)};
    checkTwoViewInputs(f.colour, f.depth, f.colour, cv::Mat(), {rgb, rgb, depth, depth});
    return frames_.emplace(i, std::move(f)).first->second;
  }
  void dropBefore(int i) {
    for (auto it = frames_.begin(); it != frames_.end();) {
      it = it->first < i ? frames_.erase(it) : std::next(it);
    }
  }

 private:
  std::string folder_;
  const TumSequence& sequence_;
  std::map<int, Frame> frames_;
};

bool isBaseline(const std::string& method) { return method == "opencv" || method == "open3d"; }

// A pnpba method's options: its BA mode, or the textbook recipe, with the same features.
TwoViewOptions pnpbaOptions(const std::string& method, int features,
                            const CovarianceModelOptions& covariance) {
  TwoViewOptions o;
  o.refinement.mode = parseBundleMode(method);
  if (method == "textbook") o = TwoViewOptions::textbookPreset();
  o.orb.num_features = features;
  o.covariance = covariance;
  return o;
}

TwoViewResult runMethod(const std::string& method, const Frame& a, const Frame& b,
                        const Camera& camera, int features,
                        const CovarianceModelOptions& covariance) {
  if (method == "opencv") {
    OpenCvBaselineOptions o;
    o.features = features;
    return estimateTwoViewOpenCv(a.colour, a.depth, b.colour, camera, o);
  }
  if (method == "open3d") {
    return estimateTwoViewOpen3dOdometry(a.colour, a.depth, b.colour, b.depth, camera);
  }
  return estimateTwoView(a.colour, a.depth, b.colour, b.depth, camera,
                         pnpbaOptions(method, features, covariance));
}

std::string cell(const PairRecord& r) {
  std::ostringstream out;
  if (r.ok) {
    out << std::fixed << std::setprecision(2) << r.error.rot_deg << "deg " << r.error.trans_cm
        << "cm";
  } else {
    out << "failed";
  }
  return out.str();
}

}  // namespace

std::string TumEvaluationOptions::validate() const {
  if (folder.empty()) return "folder: none given";
  if (max_gap < 1) return "max gap must be >= 1";
  for (int k : gaps) {
    if (k < 1) return "gaps must be >= 1";
  }
  if (!std::isfinite(gt_offset_s)) return "gt offset must be finite";
  if (!(features > 0)) return "features must be > 0";
  if (methods.empty()) return "methods: no method given";
  if (std::string c = covariance.validate(); !c.empty()) return c;
  for (const std::string& m : methods) {
    if (m == "opencv" || m == "open3d") continue;
    try {
      parseBundleMode(m);
    } catch (const Error&) {
      return "methods: unknown method '" + m +
             "' (BA modes none, pose, textbook, two-camera, rgbd; baselines opencv, open3d)";
    }
  }
  return "";
}

TumEvaluation evaluateTumSequence(const TumEvaluationOptions& options,
                                  const std::function<void(const std::string&)>& progress) {
  const std::string problem = options.validate();
  if (!problem.empty()) throw Error(problem);
  const SequenceCamera sequence_camera = sequenceCamera(options.folder, options.camera_path);
  const Camera& camera = sequence_camera.camera;
  const TumSequence seq = loadTumSequence(options.folder, options.gt_offset_s);

  TumEvaluation ev;
  ev.folder = options.folder;
  ev.gt_offset_s = options.gt_offset_s;
  ev.camera = sequence_camera.source;
  std::vector<int> gaps = options.gaps;
  if (gaps.empty()) {
    for (int k = 1; k <= options.max_gap; ++k) gaps.push_back(k);
  }
  std::sort(gaps.begin(), gaps.end());
  gaps.erase(std::unique(gaps.begin(), gaps.end()), gaps.end());
  ev.max_gap = gaps.back();
  ev.methods = options.methods;
  ev.frames = static_cast<int>(seq.frames.size());
  ev.frames_without_ground_truth = seq.frames_without_ground_truth;
  ev.frames_missing_files = seq.frames_missing_files;
  for (const TumFrame& f : seq.frames) ev.stamps.push_back(f.rgb_stamp);
  if (!seq.ground_truth.empty()) ev.first_pose = seq.ground_truth[0];

  // Every pair's time is its own: Open3D's plugin, which a pnpba method whose depth path takes
  // one of Open3D's steps may open, opens here once rather than inside the first pair that needs
  // it (where it was that pair's largest stage, about 0.1 s), as latency_bench does. A missing
  // plugin fails here as that pair would have. The default methods open none.
  const bool may_open_open3d =
      std::any_of(options.methods.begin(), options.methods.end(), [&](const std::string& m) {
        return !isBaseline(m) &&
               depthPathOpensOpen3d(pnpbaOptions(m, options.features, options.covariance));
      });
  if (may_open_open3d) ev.plugin_load_ms = preloadDepthRegistration();

  std::map<std::string, std::vector<PairOutcome>> outcomes;
  FrameCache cache(options.folder, seq);
  for (int i = 0; i < ev.frames; ++i) {
    cache.dropBefore(i);
    for (int k : gaps) {
      const int j = i + k;
      if (j >= ev.frames) break;
      if (!seq.ground_truth[i] || !seq.ground_truth[j]) continue;
      const SE3Quat truth = relativePose(*seq.ground_truth[i], *seq.ground_truth[j]);
      const Frame& a = cache.get(i);
      const Frame& b = cache.get(j);
      std::ostringstream line;
      line << "pair " << std::setw(3) << i << "-" << std::setw(3) << j << ":";
      for (const std::string& m : options.methods) {
        const TwoViewResult r = runMethod(m, a, b, camera, options.features, options.covariance);
        PairRecord rec;
        rec.i = i, rec.j = j, rec.k = k, rec.method = m, rec.ok = r.ok, rec.failure = r.failure;
        rec.time_ms = r.times_ms.total_ms, rec.inliers = r.counts.inliers;
        if (r.ok) rec.error = relativePoseError(r.T_21, truth);
        PairOutcome outcome{rec.ok, rec.error, rec.time_ms, false, {}};
        rec.motion = relativePoseError(truth, SE3Quat());
        if (r.ok && r.covariance_ok) {
          outcome.has_covariance = rec.has_covariance = true;
          outcome.fit = covarianceFit(r.T_21, truth, r.covariance);
          rec.nees = outcome.fit.nees;
          const PoseSigmas sigma = poseSigmas(r.covariance);
          rec.sigma_deg = sigma.deg, rec.sigma_cm = sigma.cm;
        }
        outcomes[m].push_back(outcome);
        if (m == options.methods.front() && k == 1 && r.ok) ev.consecutive[i] = r.T_21;
        line << "  " << m << " " << cell(rec);
        ev.records.push_back(std::move(rec));
      }
      if (progress) progress(line.str());
    }
  }
  for (const std::string& m : options.methods) ev.summaries[m] = summarize(outcomes[m]);
  return ev;
}

namespace {

// An error in the table's 9-wide columns: three decimals, or a power of ten for the far-off
// poses a baseline returns (OpenCV's PnP on wide texture-poor pairs: translations of 1e13 cm),
// which would otherwise run into the next column.
std::string errorCell(double value) {
  char text[32];
  std::snprintf(text, sizeof text, std::abs(value) < 1e4 ? "%9.3f" : "%9.2e", value);
  return text;
}

}  // namespace

std::string summaryTable(const TumEvaluation& ev) {
  std::ostringstream out;
  out << std::left << std::setw(11) << "method" << std::right << std::setw(9) << "med rot"
      << std::setw(9) << "med cm" << std::setw(9) << "mean rot" << std::setw(9) << "mean cm"
      << std::setw(9) << "max rot" << std::setw(9) << "max cm" << std::setw(10) << "1deg/2cm"
      << std::setw(10) << "2deg/5cm" << std::setw(10) << "5deg/20cm" << std::setw(7) << "wrong"
      << std::setw(6) << "fail" << std::setw(9) << "med ms" << std::setw(9) << "p95 ms"
      << std::setw(9) << "max ms" << std::setw(10) << "NEES med" << std::setw(7) << "in95"
      << std::setw(8) << "rot2s" << std::setw(8) << "trans2s"
      << "\n";
  for (const std::string& m : ev.methods) {
    const MethodSummary& s = ev.summaries.at(m);
    const int good = static_cast<int>(std::lround(s.success_rate * s.pairs));
    const std::string of = "/" + std::to_string(s.pairs);
    out << std::left << std::setw(11) << m << std::right << std::fixed;
    for (double e : {s.median_rot_deg, s.median_trans_cm, s.mean_rot_deg, s.mean_trans_cm,
                     s.max_rot_deg, s.max_trans_cm}) {
      out << errorCell(e);
    }
    out << std::setw(10) << (std::to_string(good) + of) << std::setw(10)
        << (std::to_string(s.within_2deg_5cm) + of) << std::setw(10)
        << (std::to_string(s.within_5deg_20cm) + of) << std::setw(7) << s.wrong << std::setw(6)
        << s.failures << std::setprecision(1) << std::setw(9) << s.median_time_ms << std::setw(9)
        << s.p95_time_ms << std::setw(9) << s.max_time_ms;
    if (s.with_covariance > 0) {
      out << std::setw(10) << s.nees_median << std::setprecision(0) << std::setw(6)
          << 100 * s.nees_inside95 << "%" << std::setw(7) << 100 * s.rot_within_2sigma << "%"
          << std::setw(7) << 100 * s.trans_within_2sigma << "%";
    } else {
      out << std::setw(10) << "-" << std::setw(7) << "-" << std::setw(8) << "-" << std::setw(8)
          << "-";
    }
    out << "\n";
  }
  out << "(wrong: a returned pose > 10 deg or > 50 cm off; fail: no pose returned; NEES of the\n"
         " reported covariance against the ground truth, in95: share below 12.59, rot2s/trans2s:\n"
         " share within twice the reported 1-sigma; '-': the method reports none)\n";
  return out.str();
}

std::string evaluationJson(const TumEvaluation& ev) {
  nlohmann::json methods;
  for (const std::string& m : ev.methods) {
    const MethodSummary& s = ev.summaries.at(m);
    methods[m] = {{"median_rot_deg", s.median_rot_deg},
                  {"median_trans_cm", s.median_trans_cm},
                  {"mean_rot_deg", s.mean_rot_deg},
                  {"mean_trans_cm", s.mean_trans_cm},
                  {"max_rot_deg", s.max_rot_deg},
                  {"max_trans_cm", s.max_trans_cm},
                  {"success_rate", s.success_rate},
                  {"within_2deg_5cm", s.within_2deg_5cm},
                  {"within_5deg_20cm", s.within_5deg_20cm},
                  {"wrong", s.wrong},
                  {"failures", s.failures},
                  {"pairs", s.pairs},
                  {"median_time_ms", s.median_time_ms},
                  {"p95_time_ms", s.p95_time_ms},
                  {"max_time_ms", s.max_time_ms}};
    if (s.with_covariance > 0) {
      methods[m]["covariance"] = {{"pairs", s.with_covariance},
                                  {"nees_median", s.nees_median},
                                  {"inside95", s.nees_inside95},
                                  {"rot_within_2sigma", s.rot_within_2sigma},
                                  {"trans_within_2sigma", s.trans_within_2sigma}};
    }
  }
  nlohmann::json pairs = nlohmann::json::array();
  for (const PairRecord& r : ev.records) {
    if (pairs.empty() || pairs.back()["i"] != r.i || pairs.back()["j"] != r.j) {
      pairs.push_back({{"i", r.i},
                       {"j", r.j},
                       {"k", r.k},
                       {"motion_deg", r.motion.rot_deg},
                       {"motion_cm", r.motion.trans_cm}});
    }
    // A failed estimate carries no pose error: "ok": false and the reason.
    pairs.back()[r.method] =
        r.ok ? nlohmann::json{{"ok", true},
                              {"rot_deg", r.error.rot_deg},
                              {"trans_cm", r.error.trans_cm},
                              {"time_ms", r.time_ms},
                              {"inliers", r.inliers}}
             : nlohmann::json{{"ok", false}, {"failure", r.failure}, {"time_ms", r.time_ms}};
    if (r.ok && r.has_covariance) {
      pairs.back()[r.method]["sigma_deg"] = r.sigma_deg;
      pairs.back()[r.method]["sigma_cm"] = r.sigma_cm;
      pairs.back()[r.method]["nees"] = r.nees;
    }
  }
  const nlohmann::json j = {{"sequence", ev.folder},
                            {"camera", ev.camera},
                            {"gt_offset_s", ev.gt_offset_s},
                            {"max_gap", ev.max_gap},
                            {"methods", methods},
                            {"pairs", pairs},
                            {"plugin_load_ms", ev.plugin_load_ms}};
  return j.dump(2) + "\n";
}

std::string evaluationCsv(const TumEvaluation& ev) {
  std::ostringstream csv;
  csv << "method,i,j,k,ok,rot_deg,trans_cm,time_ms,inliers,failure\n";
  for (const PairRecord& r : ev.records) {
    csv << r.method << "," << r.i << "," << r.j << "," << r.k << "," << (r.ok ? 1 : 0) << ","
        << (r.ok ? r.error.rot_deg : NAN) << "," << (r.ok ? r.error.trans_cm : NAN) << ","
        << r.time_ms << "," << r.inliers << ",\"" << r.failure << "\"\n";
  }
  return csv.str();
}

std::string chainedTrajectory(const TumEvaluation& ev, int* gaps) {
  // T_wc(i+1) = T_wc(i) * T_(i+1)i^-1.
  SE3Quat T_wc = ev.first_pose ? *ev.first_pose : SE3Quat();
  *gaps = 0;
  std::ostringstream traj;
  traj << "# " << ev.methods.front()
       << " estimates chained from frame 0; stamp tx ty tz qx qy qz qw\n";
  const int n = static_cast<int>(ev.stamps.size());
  for (int i = 0; i < n; ++i) {
    traj << formatTumPose(ev.stamps[i], T_wc) << "\n";
    auto it = ev.consecutive.find(i);
    if (it != ev.consecutive.end()) {
      T_wc = T_wc * it->second.inverse();
    } else if (i + 1 < n) {
      ++*gaps;
    }
  }
  return traj.str();
}

}  // namespace pnpba
