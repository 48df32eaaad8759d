#include "pnpba/direct/direct_ba.h"

#include <chrono>
#include <cmath>
#include <fstream>
#include <ostream>
#include <sstream>

#include "pnpba/core/error.h"
#include "pnpba/core/parse_number.h"

namespace pnpba {

namespace {

std::vector<double> numbersOnLine(const std::string& line, const std::string& where) {
  std::istringstream in(line);
  std::vector<double> values;
  for (std::string token; in >> token;) values.push_back(numberOrThrow(token, where));
  return values;
}

// Calls f(line, where) for each non-blank line.
template <typename F>
void forLines(const std::string& path, F f) {
  std::ifstream in(path);
  if (!in) throw Error(path + ": cannot open file");
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    f(line, path + ":" + std::to_string(n) + ": ");
  }
}

}  // namespace

std::vector<DirectPose> readDirectPoses(const std::string& path) {
  std::vector<DirectPose> poses;
  forLines(path, [&](const std::string& line, const std::string& where) {
    const std::vector<double> v = numbersOnLine(line, where);
    if (v.size() != 8) {
      throw Error(where + "expected 8 numbers (timestamp tx ty tz qx qy qz qw), got " +
                  std::to_string(v.size()));
    }
    const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
    if (!(std::abs(q.norm() - 1.0) < 1e-3)) throw Error(where + "quaternion is not unit length");
    std::istringstream in(line);
    DirectPose p;
    in >> p.stamp;
    p.T_cw = SE3Quat(q.normalized(), Eigen::Vector3d(v[1], v[2], v[3]));
    poses.push_back(p);
  });
  if (poses.empty()) throw Error(path + ": no poses");
  return poses;
}

std::vector<DirectPoint> readDirectPoints(const std::string& path) {
  std::vector<DirectPoint> points;
  forLines(path, [&](const std::string& line, const std::string& where) {
    const std::vector<double> v = numbersOnLine(line, where);
    if (v.size() != 19) {
      throw Error(where + "expected 19 numbers (x y z and 16 intensities), got " +
                  std::to_string(v.size()));
    }
    DirectPoint p;
    p.Pw = Eigen::Vector3d(v[0], v[1], v[2]);
    for (int k = 0; k < 16; ++k) p.patch[k] = v[3 + k];
    points.push_back(p);
  });
  if (points.empty()) throw Error(path + ": no points");
  return points;
}

void writeDirectPoses(std::ostream& out, const std::vector<DirectPose>& poses) {
  char line[256];
  for (const DirectPose& p : poses) {
    const Eigen::Vector3d& t = p.T_cw.translation();
    const Eigen::Quaterniond& q = p.T_cw.rotation();
    std::snprintf(line, sizeof line, " %.9g %.9g %.9g %.9g %.9g %.9g %.9g\n", t.x(), t.y(), t.z(),
                  q.x(), q.y(), q.z(), q.w());
    out << p.stamp << line;
  }
}

std::string DirectBaOptions::validate() const {
  if (!(huber_delta > 0)) return "huber delta must be > 0";
  if (iterations < 1) return "iterations must be >= 1";
  if (iterations_per_round < 0) return "iterations per round must be >= 0";
  if (threads < 1) return "threads must be >= 1";
  if (patch_size < 2 || patch_size > 4) return "patch size must be 2, 3 or 4";
  return "";
}

namespace {

void checkProblem(const DirectBaProblem& p) {
  if (p.images.size() != p.poses.size()) {
    throw Error(std::to_string(p.poses.size()) + " poses but " + std::to_string(p.images.size()) +
                " images");
  }
  for (const auto& image : p.images) {
    if (!image || image->width < 5 || image->height < 5)
      throw Error("image is missing or too small");
  }
}

// The graph: pose k = vertex k, point j = vertex poses + j (marginalised), one edge per
// (point, pose), edge id = j * poses + k.
// Information of a centred n x n window of the 4x4 patch (offsets -2..1): 1 on its pixels.
Eigen::Matrix<double, 16, 16> windowInformation(int n) {
  Eigen::Matrix<double, 16, 16> info = Eigen::Matrix<double, 16, 16>::Zero();
  const int lo = n == 4 ? -2 : -1, hi = n == 2 ? 0 : 1;  // 2: {-1,0}, 3: {-1,0,1}, 4: {-2..1}
  for (int dx = -2; dx <= 1; ++dx)
    for (int dy = -2; dy <= 1; ++dy) {
      if (dx >= lo && dx <= hi && dy >= lo && dy <= hi) {
        const int k = 4 * (dx + 2) + (dy + 2);
        info(k, k) = 1.0;
      }
    }
  return info;
}

void buildGraph(SparseOptimizer& optimizer, const DirectBaProblem& p, double huber_delta,
                bool fix_first_pose, bool inverse_depth = false, int patch_size = 4) {
  const Eigen::Matrix<double, 16, 16> information = windowInformation(patch_size);
  const int n_poses = static_cast<int>(p.poses.size());
  for (int k = 0; k < n_poses; ++k) {
    auto* v = new VertexSE3Expmap();
    v->setId(k);
    v->setEstimate(p.poses[k].T_cw);
    v->setFixed(fix_first_pose && k == 0);
    optimizer.addVertex(v);
  }
  const SE3Quat& T_hw = p.poses[0].T_cw;  // host of inverse-depth points
  for (size_t j = 0; j < p.points.size(); ++j) {
    const int id = n_poses + static_cast<int>(j);
    Vertex* point = nullptr;
    if (inverse_depth) {
      const Eigen::Vector3d X = T_hw.map(p.points[j].Pw);
      if (!(X.z() > 1e-6)) {
        throw Error("point " + std::to_string(j) + " is behind camera 0: no inverse depth");
      }
      auto* v = new VertexInverseDepthPoint();
      v->setEstimate(Eigen::Vector3d(X.x() / X.z(), X.y() / X.z(), 1.0 / X.z()));
      point = v;
    } else {
      auto* v = new VertexPointXYZ();
      v->setEstimate(p.points[j].Pw);
      point = v;
    }
    point->setId(id);
    point->setMarginalized(true);
    optimizer.addVertex(point);
    for (int k = 0; k < n_poses; ++k) {
      Edge* edge = nullptr;
      PhotometricObservation* obs = nullptr;
      if (inverse_depth) {
        auto* e = new EdgePhotometricInverseDepth();
        e->setHost(T_hw);
        e->setMeasurement(p.points[j].patch);
        e->setInformation(information);
        edge = e, obs = e;
      } else {
        auto* e = new EdgePhotometric();
        e->setMeasurement(p.points[j].patch);
        e->setInformation(information);
        edge = e, obs = e;
      }
      edge->setId(static_cast<int>(j) * n_poses + k);
      edge->setVertex(0, point);
      edge->setVertex(1, optimizer.vertex(k));
      obs->setImage(p.images[k].get());
      obs->setIntrinsics(p.fx, p.fy, p.cx, p.cy);
      edge->setRobustKernel(new RobustKernelHuber(huber_delta));
      optimizer.addEdge(edge);
    }
  }
}

// Level 0 for the edges whose patch is inside their image now, 1 for the others.
size_t decideActiveSet(SparseOptimizer& optimizer) {
  size_t active = 0;
  for (Edge* e : optimizer.edges()) {
    const bool inside = dynamic_cast<const PhotometricObservation&>(*e).patchInside();
    e->setLevel(inside ? 0 : 1);
    active += inside;
  }
  return active;
}

}  // namespace

DirectBaEvaluation evaluateDirectBa(const DirectBaProblem& problem, double huber_delta) {
  checkProblem(problem);
  SparseOptimizer optimizer;
  buildGraph(optimizer, problem, huber_delta, false);
  DirectBaEvaluation ev;
  ev.edges = optimizer.numEdges();
  ev.active_edges = decideActiveSet(optimizer);
  optimizer.initializeOptimization(0);
  optimizer.computeActiveErrors();
  ev.robust_cost = 0.5 * optimizer.activeRobustChi2();
  ev.plain_cost = 0.5 * optimizer.activeChi2();
  double abs_sum = 0;
  for (Edge* e : optimizer.activeEdges()) {
    const Eigen::Map<const PatchVector> r(e->errorData());
    abs_sum += r.cwiseAbs().sum();
  }
  ev.mean_abs_residual = ev.active_edges > 0 ? abs_sum / (16.0 * ev.active_edges) : 0;
  return ev;
}

DirectBaSummary solveDirectBa(DirectBaProblem& problem, const DirectBaOptions& options) {
  const std::string bad = options.validate();
  if (!bad.empty()) throw Error(bad);
  checkProblem(problem);
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  SparseOptimizer optimizer;
  optimizer.setSolverBackend(SolverBackend::kNative);
  optimizer.options().num_threads = options.threads;
  if (options.inverse_depth && !options.fix_first_pose) {
    throw Error("inverse-depth points need camera 0 (their host) fixed");
  }
  buildGraph(optimizer, problem, options.huber_delta, options.fix_first_pose, options.inverse_depth,
             options.patch_size);
  DirectBaSummary s;
  s.edges = optimizer.numEdges();
  s.active_edges_initial = decideActiveSet(optimizer);
  optimizer.initializeOptimization(0);
  optimizer.computeActiveErrors();
  s.initial_cost = 0.5 * optimizer.activeRobustChi2();
  size_t active = s.active_edges_initial;
  optimizer.setIterationCallback([&](const IterationStats& it) {
    if (options.progress) {
      options.progress({s.iterations + it.iteration + 1, 0.5 * it.chi2, active, elapsed()});
    }
  });
  const int per_round =
      options.iterations_per_round > 0 ? options.iterations_per_round : options.iterations;
  while (s.iterations < options.iterations) {
    if (s.rounds > 0) {
      active = decideActiveSet(optimizer);  // between rounds only: fixed within a round
      optimizer.initializeOptimization(0);
    }
    ++s.rounds;
    const int done = optimizer.optimize(std::min(per_round, options.iterations - s.iterations));
    s.iterations += done;
    if (done < per_round) break;  // converged within the round
  }
  optimizer.initializeOptimization(0);
  optimizer.computeActiveErrors();
  s.active_edges_final = optimizer.activeEdges().size();
  s.final_cost = 0.5 * optimizer.activeRobustChi2();
  for (size_t k = 0; k < problem.poses.size(); ++k) {
    const SE3Quat& before = problem.poses[k].T_cw;
    const SE3Quat after =
        static_cast<VertexSE3Expmap*>(optimizer.vertex(static_cast<int>(k)))->estimate();
    const Eigen::AngleAxisd d((after * before.inverse()).rotation());
    s.pose_change.push_back(
        {d.angle() * 180.0 / M_PI,
         (after.inverse().translation() - before.inverse().translation()).norm()});
    problem.poses[k].T_cw = after;
  }
  const int n_poses = static_cast<int>(problem.poses.size());
  for (size_t j = 0; j < problem.points.size(); ++j) {
    const Vertex* v = optimizer.vertex(n_poses + static_cast<int>(j));
    Eigen::Vector3d after;
    if (options.inverse_depth) {
      const Eigen::Vector3d q = static_cast<const VertexInverseDepthPoint*>(v)->estimate();
      after = problem.poses[0].T_cw.inverse().map(Eigen::Vector3d(q.x(), q.y(), 1.0) / q.z());
    } else {
      after = static_cast<const VertexPointXYZ*>(v)->estimate();
    }
    s.max_point_motion_m = std::max(s.max_point_motion_m, (after - problem.points[j].Pw).norm());
    problem.points[j].Pw = after;
  }
  s.time_s = elapsed();
  return s;
}

}  // namespace pnpba
