// bal_bench: pnpba's dedicated BAL solver side by side with Ceres, in one process, same threads:
//   ceres    Ceres's bundle_adjuster set-up built from the installed Ceres (Snavely autodiff cost
//            on the raw angle-axis cameras, points eliminated first; tests/support), with the
//            linear solver given (Ceres's best per problem: dense_schur for Ladybug-49,
//            sparse_schur or iterative_schur for the generated ones, whichever is faster)
//   pnpba    solveBal with solver "pnpba" (linear solver auto)
// on problem-49-7776-pre (Ladybug, normalised as bundle_adjuster does) and on generated
// problems (bal_synthetic) of growing size.
// Reports medians over repetitions of two times from both per-iteration tables (set-up
// included): to first reach Ceres's final cost (+1e-6 relative), and to first come within 0.1 %
// of the converged cost (the lower of the two final costs); iterations, final cost, peak
// resident memory above the problem's (VmHWM, reset before each run) per observation, and the
// ratios.
//
//   build/bench/bal_bench [--repetitions 3] [--threads 2] [--cameras 50,300,1000,3000]
//       [--points-per-camera 60] [--track 5] [--json R.json] [--plot R.png] [--no-ladybug]
#include <malloc.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <string>

#include "bench_output.h"
#include "guarded_main.h"
#include "pnpba/bal/bal_problem.h"
#include "pnpba/bal/bal_solver.h"
#include "pnpba/bal/bal_synthetic.h"
#include "snavely_autodiff.h"

namespace {

constexpr double kTargetSlack = 1e-6;  // "reached" = cost <= Ceres's final * (1 + this)
constexpr double kNearSlack = 1e-3;    // "within 0.1 %" = cost <= converged * (1 + this)

// Returns freed heap to the system, then resets the peak resident size, so each run's peak
// above the resident size before it is its own working memory.
void resetPeakMemory() {
  malloc_trim(0);
  std::ofstream("/proc/self/clear_refs") << "5";
}

double statusMb(const char* key) {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);) {
    if (line.rfind(key, 0) == 0) return std::stod(line.substr(std::string(key).size())) / 1024.0;
  }
  return 0;
}

struct Run {
  double to_target_s = -1, total_s = 0, final_cost = 0, memory_mb = 0;
  int iterations = 0;
  std::vector<std::pair<double, double>> table;  // (cumulative time, cost)
};

Run runCeres(const pnpba::BalProblem& original, ceres::LinearSolverType solver, int threads,
             int max_iterations) {
  pnpba::BalProblem p = original;
  resetPeakMemory();
  const double before = statusMb("VmRSS:");
  const auto start = std::chrono::steady_clock::now();
  ceres::Problem problem;
  for (const pnpba::BalObservation& o : p.observations) {
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<pnpba::test::SnavelyResidual, 2, 9, 3>(
                                 new pnpba::test::SnavelyResidual(o.u, o.v)),
                             nullptr, &p.cameras[9 * o.camera], &p.points[3 * o.point]);
  }
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  for (int q = 0; q < p.num_points; ++q) ordering->AddElementToGroup(&p.points[3 * q], 0);
  for (int c = 0; c < p.num_cameras; ++c) ordering->AddElementToGroup(&p.cameras[9 * c], 1);
  ceres::Solver::Options options;
  options.linear_solver_type = solver;
  if (solver == ceres::ITERATIVE_SCHUR) options.preconditioner_type = ceres::SCHUR_JACOBI;
  options.linear_solver_ordering = ordering;
  options.max_num_iterations = max_iterations;
  options.num_threads = threads;
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  const double setup_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ceres::Solve(options, &problem, &summary);
  Run r;
  r.total_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.final_cost = summary.final_cost;
  r.iterations = static_cast<int>(summary.iterations.size()) - 1;
  for (const auto& it : summary.iterations) {
    r.table.emplace_back(
        setup_s + summary.preprocessor_time_in_seconds + it.cumulative_time_in_seconds, it.cost);
  }
  r.memory_mb = statusMb("VmHWM:") - before;
  return r;
}

Run runPnpba(const pnpba::BalProblem& original, int threads, int max_iterations,
             pnpba::BalSolveSummary* out = nullptr) {
  pnpba::BalProblem p = original;
  resetPeakMemory();
  const double before = statusMb("VmRSS:");
  pnpba::BalSolveOptions o;
  o.threads = threads, o.iterations = max_iterations;
  const pnpba::BalSolveSummary s = pnpba::solveBal(p, o);
  Run r;
  r.total_s = s.time_s;
  r.final_cost = s.final_cost;
  r.iterations = s.iterations;
  for (const pnpba::BalIteration& it : s.table) r.table.emplace_back(it.cum_time_s, it.cost);
  r.memory_mb = statusMb("VmHWM:") - before;
  if (out) *out = s;
  return r;
}

double timeToReach(const Run& r, double target) {
  for (const auto& [t, cost] : r.table) {
    if (cost <= target) return t;
  }
  return -1;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

struct Row {
  std::string problem, ceres_solver, pnpba_linear;
  int cameras = 0;
  size_t observations = 0;
  double ceres_s = 0, pnpba_s = 0, ceres_cost = 0, pnpba_cost = 0;
  double ceres_near_s = 0, pnpba_near_s = 0;  // to within 0.1 % of the converged cost
  double ceres_bytes_per_obs = 0, pnpba_bytes_per_obs = 0;
  int ceres_iterations = 0, pnpba_iterations = 0;
};

// Medians over repetitions of both solvers on one problem; the target is each repetition's
// Ceres final cost.
Row compare(const std::string& name, const pnpba::BalProblem& problem,
            const std::vector<ceres::LinearSolverType>& ceres_solvers, int threads, int repetitions,
            int max_iterations) {
  Row row;
  row.problem = name;
  row.cameras = problem.num_cameras;
  row.observations = problem.observations.size();
  // Ceres's best configuration: the fastest to its own final cost.
  double best = 1e300;
  ceres::LinearSolverType chosen = ceres_solvers.front();
  std::vector<Run> ceres_runs;
  for (ceres::LinearSolverType s : ceres_solvers) {
    std::vector<Run> runs;
    for (int i = 0; i < repetitions; ++i)
      runs.push_back(runCeres(problem, s, threads, max_iterations));
    std::vector<double> t;
    for (const Run& r : runs) t.push_back(timeToReach(r, r.final_cost * (1 + kTargetSlack)));
    if (median(t) < best) best = median(t), chosen = s, ceres_runs = runs;
  }
  row.ceres_solver = ceres::LinearSolverTypeToString(chosen);
  std::vector<double> ct, pt, cm, pm, cc, pc, cn, pn;
  for (int i = 0; i < repetitions; ++i) {
    const Run& c = ceres_runs[i];
    pnpba::BalSolveSummary summary;
    const Run p = runPnpba(problem, threads, max_iterations, &summary);
    row.pnpba_linear = summary.linear_solver;
    const double target = c.final_cost * (1 + kTargetSlack);
    ct.push_back(timeToReach(c, target));
    const double reached = timeToReach(p, target);
    pt.push_back(reached < 0 ? 1e9 : reached);
    const double near = std::min(c.final_cost, p.final_cost) * (1 + kNearSlack);
    cn.push_back(timeToReach(c, near)), pn.push_back(timeToReach(p, near));
    cm.push_back(c.memory_mb), pm.push_back(p.memory_mb);
    cc.push_back(c.final_cost), pc.push_back(p.final_cost);
    row.ceres_iterations = c.iterations, row.pnpba_iterations = p.iterations;
  }
  row.ceres_s = median(ct), row.pnpba_s = median(pt);
  row.ceres_near_s = median(cn), row.pnpba_near_s = median(pn);
  row.ceres_cost = median(cc), row.pnpba_cost = median(pc);
  row.ceres_bytes_per_obs = median(cm) * 1048576.0 / row.observations;
  row.pnpba_bytes_per_obs = median(pm) * 1048576.0 / row.observations;
  return row;
}

void print(const Row& r) {
  std::printf(
      "%-24s %6d %9zu %-16s %9.3f %4d %-7s %9.3f %4d %6.3f %10.6e %10.6e %7.0f %7.0f | 0.1%%: "
      "ceres %7.3f pnpba %7.3f ratio %6.3f\n",
      r.problem.c_str(), r.cameras, r.observations, r.ceres_solver.c_str(), r.ceres_s,
      r.ceres_iterations, r.pnpba_linear.c_str(), r.pnpba_s < 1e8 ? r.pnpba_s : -1.0,
      r.pnpba_iterations, r.pnpba_s < 1e8 ? r.pnpba_s / r.ceres_s : -1.0, r.ceres_cost,
      r.pnpba_cost, r.ceres_bytes_per_obs, r.pnpba_bytes_per_obs, r.ceres_near_s, r.pnpba_near_s,
      r.ceres_near_s > 0 ? r.pnpba_near_s / r.ceres_near_s : -1.0);
  std::fflush(stdout);
}

// Time to Ceres's final cost against observations, both solvers, log-log.
void plot(const std::string& path, const std::vector<Row>& rows) {
  const int W = 640, H = 420, L = 70, B = 50, T = 30, R = 20;
  cv::Mat img(H, W, CV_8UC3, cv::Scalar::all(255));
  double xmin = 1e300, xmax = 0, ymin = 1e300, ymax = 0;
  for (const Row& r : rows) {
    xmin = std::min(xmin, double(r.observations)), xmax = std::max(xmax, double(r.observations));
    for (double y : {r.ceres_s, r.pnpba_s}) {
      if (y > 0 && y < 1e8) ymin = std::min(ymin, y), ymax = std::max(ymax, y);
    }
  }
  xmin /= 1.5, xmax *= 1.5, ymin /= 1.5, ymax *= 1.5;
  auto at = [&](double x, double y) {
    return cv::Point(L + int((std::log(x / xmin) / std::log(xmax / xmin)) * (W - L - R)),
                     H - B - int((std::log(y / ymin) / std::log(ymax / ymin)) * (H - B - T)));
  };
  cv::rectangle(img, cv::Point(L, T), cv::Point(W - R, H - B), cv::Scalar::all(0));
  const auto font = cv::FONT_HERSHEY_SIMPLEX;
  for (double y = std::pow(10, std::floor(std::log10(ymin))); y <= ymax; y *= 10) {
    if (y < ymin) continue;
    char text[32];
    std::snprintf(text, sizeof text, "%g s", y);
    cv::putText(img, text, at(xmin, y) + cv::Point(-65, 5), font, 0.4, cv::Scalar::all(0));
    cv::line(img, at(xmin, y), at(xmax, y), cv::Scalar::all(220));
  }
  for (double x = std::pow(10, std::ceil(std::log10(xmin))); x <= xmax; x *= 10) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", x);
    cv::putText(img, text, at(x, ymin) + cv::Point(-15, 20), font, 0.4, cv::Scalar::all(0));
  }
  cv::putText(img, "observations", cv::Point(W / 2 - 40, H - 10), font, 0.45, cv::Scalar::all(0));
  cv::putText(img, "time to Ceres's final cost: Ceres (red), pnpba (green)", cv::Point(L, 20), font,
              0.45, cv::Scalar::all(0));
  for (int k = 0; k < 2; ++k) {
    const cv::Scalar colour = k == 0 ? cv::Scalar(40, 40, 220) : cv::Scalar(40, 160, 40);
    cv::Point last(-1, -1);
    for (const Row& r : rows) {
      if (r.problem.rfind("generated", 0) != 0) continue;
      const double y = k == 0 ? r.ceres_s : r.pnpba_s;
      if (!(y > 0 && y < 1e8)) continue;
      const cv::Point p = at(double(r.observations), y);
      cv::circle(img, p, 4, colour, cv::FILLED);
      if (last.x >= 0) cv::line(img, last, p, colour, 2);
      last = p;
    }
  }
  pnpba::bench::writePngFile(path, img);
}

}  // namespace

// The bench itself (main: guarded_main.h).
static int benchMain(int argc, char** argv) {
  CLI::App app{"pnpba's BAL solver against Ceres on Ladybug-49 and generated problems."};
  int repetitions = 3, threads = 2, points_per_camera = 60, track = 5, max_iterations = 50;
  std::string cameras_text = "50,300,1000,3000", json_path, plot_path;
  bool no_ladybug = false;
  app.add_option("--repetitions", repetitions)->capture_default_str();
  app.add_option("--threads", threads)->capture_default_str();
  app.add_option("--cameras", cameras_text, "generated problem sizes")->capture_default_str();
  app.add_option("--points-per-camera", points_per_camera)->capture_default_str();
  app.add_option("--track", track, "observations per point")->capture_default_str();
  app.add_option("--iterations", max_iterations)->capture_default_str();
  app.add_option("--json", json_path);
  app.add_option("--plot", plot_path);
  app.add_flag("--no-ladybug", no_ladybug);
  CLI11_PARSE(app, argc, argv);
  pnpba::bench::checkOutputPaths({json_path, plot_path});

  std::printf("%-24s %6s %9s %-16s %9s %4s %-7s %9s %4s %6s %12s %12s %7s %7s\n", "problem", "cams",
              "obs", "ceres", "ceres_s", "it", "pnpba", "pnpba_s", "it", "ratio", "ceres_cost",
              "pnpba_cost", "B/obs_c", "B/obs_p");
  std::vector<Row> rows;
  if (!no_ladybug) {
    const std::string path = std::string(PNPBA_SHARED_DATA) + "/bal/problem-49-7776-pre.txt";
    if (std::ifstream(path)) {
      // Normalised as Ceres's bundle_adjuster always does (projections are unchanged).
      pnpba::BalProblem ladybug = pnpba::readBal(path);
      pnpba::normalizeBal(ladybug);
      rows.push_back(compare("ladybug-49-7776", ladybug, {ceres::DENSE_SCHUR, ceres::SPARSE_SCHUR},
                             threads, repetitions, max_iterations));
      print(rows.back());
    }
  }
  std::stringstream list(cameras_text);
  for (std::string item; std::getline(list, item, ',');) {
    pnpba::BalSyntheticOptions o;
    o.cameras = std::stoi(item);
    o.points = points_per_camera * o.cameras;
    o.observations_per_point = track;
    const pnpba::BalSyntheticProblem g = pnpba::generateBalProblem(o);
    std::vector<ceres::LinearSolverType> solvers = {ceres::SPARSE_SCHUR, ceres::ITERATIVE_SCHUR};
    if (o.cameras <= 200) solvers.insert(solvers.begin(), ceres::DENSE_SCHUR);
    rows.push_back(
        compare("generated-" + item, g.start, solvers, threads, repetitions, max_iterations));
    print(rows.back());
  }
  if (!json_path.empty()) {
    nlohmann::json j = nlohmann::json::array();
    for (const Row& r : rows) {
      j.push_back({{"problem", r.problem},
                   {"cameras", r.cameras},
                   {"observations", r.observations},
                   {"ceres_solver", r.ceres_solver},
                   {"ceres_s", r.ceres_s},
                   {"ceres_iterations", r.ceres_iterations},
                   {"ceres_final_cost", r.ceres_cost},
                   {"ceres_bytes_per_observation", r.ceres_bytes_per_obs},
                   {"pnpba_linear_solver", r.pnpba_linear},
                   {"pnpba_s", r.pnpba_s < 1e8 ? r.pnpba_s : -1.0},
                   {"pnpba_iterations", r.pnpba_iterations},
                   {"pnpba_final_cost", r.pnpba_cost},
                   {"pnpba_bytes_per_observation", r.pnpba_bytes_per_obs},
                   {"ceres_s_within_0p1_percent", r.ceres_near_s},
                   {"pnpba_s_within_0p1_percent", r.pnpba_near_s},
                   {"threads", threads}});
    }
    pnpba::bench::writeJsonFile(json_path, j, 2);
  }
  if (!plot_path.empty()) plot(plot_path, rows);
  return 0;
}

int main(int argc, char** argv) {
  return pnpba::bench::guardedMain("bal_bench", benchMain, argc, argv);
}
