// The accuracy benches over rendered pairs (moving_object_bench, orbit_bench): the methods they
// run side by side and one result's verdict against the exact truth, counted:
//   ok       within 2 deg and 5 cm
//   refused  no pose returned
//   off      returned, neither ok nor wrong
//   wrong    returned but more than 10 deg or 50 cm off
#pragma once

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "percentile.h"
#include "pnpba/core/error.h"
#include "pnpba/core/output_file.h"
#include "pnpba/evaluation/evaluation.h"
#include "pnpba/evaluation/opencv_baseline.h"
#include "pnpba/pipeline/two_view.h"
#include "pnpba/synthetic/synthetic_pair.h"

namespace pnpba::bench {

struct PoseTally {
  int ok = 0, refused = 0, off = 0, wrong = 0;
  double max_off_cm = 0;         // the largest translation error of a returned pose not ok
  std::vector<double> times_ms;  // in-process, per pair
};

// The options both benches take. `pairs` names what --seeds counts, `json` what --json holds.
struct AccuracyRunOptions {
  int seeds = 1;
  std::string methods = "default", json_path;
  bool verbose = false;
};

inline void addAccuracyRunOptions(CLI::App& app, AccuracyRunOptions* o, const std::string& pairs,
                                  const std::string& json) {
  app.add_option("--seeds", o->seeds, pairs)->capture_default_str()->check(CLI::Range(1, 100));
  app.add_option("--methods", o->methods, "default, opencv (comma list)")->capture_default_str();
  app.add_option("--json", o->json_path, "write " + json);
  app.add_flag("--verbose", o->verbose, "a line per pair");
}

// "default,opencv" and the like; throws Error naming another.
inline std::vector<std::string> parseMethods(const std::string& text) {
  std::vector<std::string> methods;
  std::stringstream in(text);
  for (std::string m; std::getline(in, m, ',');) {
    if (m != "default" && m != "opencv") {
      throw Error("--methods: unknown method '" + m + "' (default, opencv)");
    }
    methods.push_back(m);
  }
  return methods;
}

// The command line parsed and its methods and --json path checked before any work: -1 to go
// on (*methods filled), else the exit code (0 after --help, 2 for a usage error). A bad method or
// output path throws Error, which the bench's guarded main reports with exit 2.
inline int parseAccuracyRun(CLI::App& app, int argc, char** argv, const AccuracyRunOptions& o,
                            std::vector<std::string>* methods) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  *methods = parseMethods(o.methods);
  if (!o.json_path.empty()) checkOutputPath(o.json_path);
  return -1;
}

// `default`: pnpba's pipeline as shipped; `opencv`: the OpenCV baseline
// (evaluation/opencv_baseline.h, the same feature count), which takes no second depth.
inline TwoViewResult estimateWith(const std::string& method, const SyntheticPair& p,
                                  const Camera& camera) {
  if (method == "opencv") {
    return estimateTwoViewOpenCv(p.view1.colour, p.view1.depth, p.view2.colour, camera,
                                 OpenCvBaselineOptions{});
  }
  return estimateTwoView(p.view1.colour, p.view1.depth, p.view2.colour, p.view2.depth, camera,
                         TwoViewOptions{});
}

// Counts r into t; returns the verdict with the error ("ok 0.21 deg 1.3 cm", "WRONG ...",
// "refused: <reason>"), for a bench's --verbose line.
inline std::string tallyResult(const TwoViewResult& r, const SE3Quat& truth, PoseTally* t) {
  t->times_ms.push_back(r.times_ms.total_ms);
  if (!r.ok) {
    ++t->refused;
    return "refused: " + r.failure.substr(0, 90);
  }
  const PoseError e = relativePoseError(r.T_21, truth);
  std::string verdict;
  if (e.rot_deg <= 2 && e.trans_cm <= 5) {
    ++t->ok, verdict = "ok";
  } else if (e.rot_deg > 10 || e.trans_cm > 50) {
    ++t->wrong, verdict = "WRONG";
  } else {
    ++t->off, verdict = "OFF";
  }
  if (verdict != "ok") t->max_off_cm = std::max(t->max_off_cm, e.trans_cm);
  char error[64];
  std::snprintf(error, sizeof error, " %.2f deg %.1f cm", e.rot_deg, e.trans_cm);
  return verdict + error;
}

// A tally's counts and times for a JSON row: ok, refused, off, wrong, p50_ms, max_ms.
inline nlohmann::json tallyJson(const PoseTally& t) {
  return {{"ok", t.ok},
          {"refused", t.refused},
          {"off", t.off},
          {"wrong", t.wrong},
          {"p50_ms", percentile(t.times_ms, 0.5)},
          {"max_ms", percentile(t.times_ms, 1.0)}};
}

// --json's file, when one was asked for: {key: rows}, written whole (output_file.h).
inline void writeRows(const AccuracyRunOptions& o, const std::string& key,
                      const nlohmann::json& rows) {
  if (o.json_path.empty()) return;
  writeOutputFile(o.json_path, [&](std::ostream& out) {
    out << nlohmann::json{{key, rows}}.dump(1) << "\n";
  });
}

}  // namespace pnpba::bench
