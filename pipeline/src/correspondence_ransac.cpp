#include "pnpba/pipeline/correspondence_ransac.h"

#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/task_arena.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <random>

#include "pnpba/core/error.h"

namespace pnpba {

namespace {

// The search runs in rounds of kBlocksPerRound blocks of kBlockIterations triples; the stop test
// runs between rounds. Both are fixed, so the thread count never changes the result.
constexpr int kBlockIterations = 512;
constexpr int kBlocksPerRound = 8;
// Distinct hypotheses each block and the search keep; the best few are refined and returned.
constexpr size_t kPoolSize = 16;
constexpr int kRefinements = 3;

struct Hypothesis {
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
  int support = 0;
  long order = 0;  // where it was drawn: breaks ties the same way on every run
};

using Points = std::vector<Eigen::Vector3d>;

int support(const Hypothesis& h, const Points& source, const Points& target, double d2) {
  int n = 0;
  for (size_t i = 0; i < source.size(); ++i)
    n += (h.R * source[i] + h.t - target[i]).squaredNorm() < d2;
  return n;
}

// The least-squares rigid pose taking the chosen source points onto their targets.
template <typename Indices>
void fitRigid(const Points& source, const Points& target, const Indices& chosen, Hypothesis* h) {
  Eigen::Matrix3Xd s(3, chosen.size()), d(3, chosen.size());
  for (size_t k = 0; k < chosen.size(); ++k) {
    s.col(k) = source[chosen[k]];
    d.col(k) = target[chosen[k]];
  }
  const Eigen::Matrix4d T = Eigen::umeyama(s, d, false);
  h->R = T.topLeftCorner<3, 3>();
  h->t = T.topRightCorner<3, 1>();
}

bool distinct(const Hypothesis& a, const Hypothesis& b, const CorrespondenceRansacOptions& o) {
  const double cos_angle = std::clamp(((a.R.transpose() * b.R).trace() - 1.0) / 2.0, -1.0, 1.0);
  return std::acos(cos_angle) * 180.0 / M_PI > o.distinct_deg || (a.t - b.t).norm() > o.distinct_m;
}

bool better(const Hypothesis& a, const Hypothesis& b) {
  return a.support != b.support ? a.support > b.support : a.order < b.order;
}

// Adds h to a pool of distinct hypotheses, best first: a hypothesis close to one already there
// replaces it only when better.
void addToPool(const Hypothesis& h, const CorrespondenceRansacOptions& o,
               std::vector<Hypothesis>* pool) {
  for (Hypothesis& p : *pool) {
    if (distinct(p, h, o)) continue;
    if (better(h, p)) p = h;
    std::sort(pool->begin(), pool->end(), better);
    return;
  }
  if (pool->size() == kPoolSize && !better(h, pool->back())) return;
  pool->push_back(h);
  std::sort(pool->begin(), pool->end(), better);
  if (pool->size() > kPoolSize) pool->pop_back();
}

bool edgesAgree(const Points& source, const Points& target, int a, int b, double similarity,
                double min_length) {
  const double ls = (source[a] - source[b]).norm();
  const double lt = (target[a] - target[b]).norm();
  return std::min(ls, lt) >= similarity * std::max(ls, lt) && std::min(ls, lt) >= min_length;
}

// One block of triples with its own generator; its distinct hypotheses go to *pool.
void searchBlock(const Points& source, const Points& target, const CorrespondenceRansacOptions& o,
                 long block, int iterations, std::vector<Hypothesis>* pool, int* scored) {
  std::mt19937 rng(o.seed * 2654435761u + static_cast<unsigned>(block));
  const int n = static_cast<int>(source.size());
  std::uniform_int_distribution<int> pick(0, n - 1);
  const double d2 = o.inlier_distance_m * o.inlier_distance_m;
  for (int it = 0; it < iterations; ++it) {
    const int a = pick(rng), b = pick(rng), c = pick(rng);
    if (a == b || a == c || b == c) continue;
    // Edges shorter than the inlier distance leave the rotation to the noise.
    if (!edgesAgree(source, target, a, b, o.edge_similarity, o.inlier_distance_m) ||
        !edgesAgree(source, target, b, c, o.edge_similarity, o.inlier_distance_m) ||
        !edgesAgree(source, target, a, c, o.edge_similarity, o.inlier_distance_m)) {
      continue;
    }
    Hypothesis h;
    fitRigid(source, target, std::array<int, 3>{a, b, c}, &h);
    if (!h.R.allFinite() || !h.t.allFinite()) continue;
    ++*scored;
    h.support = support(h, source, target, d2);
    h.order = block * kBlockIterations + it;
    if (h.support >= 3) addToPool(h, o, pool);
  }
}

}  // namespace

std::string CorrespondenceRansacOptions::validate() const {
  if (!(inlier_distance_m > 0) || !std::isfinite(inlier_distance_m)) {
    return "correspondence RANSAC inlier distance must be > 0";
  }
  if (!(edge_similarity > 0 && edge_similarity < 1)) {
    return "correspondence RANSAC edge similarity must be in (0, 1)";
  }
  if (max_iterations < 1) return "correspondence RANSAC iterations must be >= 1";
  if (!(confidence > 0 && confidence < 1)) {
    return "correspondence RANSAC confidence must be in (0, 1)";
  }
  if (max_candidates < 1) return "correspondence RANSAC candidates must be >= 1";
  if (!(rival_support > 0 && rival_support <= 1)) {
    return "correspondence RANSAC rival support must be in (0, 1]";
  }
  if (!(distinct_deg > 0) || !(distinct_m > 0)) {
    return "correspondence RANSAC distinct thresholds must be > 0";
  }
  if (threads < 1) return "correspondence RANSAC threads must be >= 1";
  return "";
}

std::vector<RigidCandidate> ransacRigidPoses(const Points& source, const Points& target,
                                             const CorrespondenceRansacOptions& o,
                                             CorrespondenceRansacStats* stats) {
  const std::string problem = o.validate();
  if (!problem.empty()) throw Error(problem);
  if (source.size() != target.size()) {
    throw Error("correspondence RANSAC: " + std::to_string(source.size()) + " source and " +
                std::to_string(target.size()) + " target points");
  }
  CorrespondenceRansacStats local_stats;
  CorrespondenceRansacStats& s = stats != nullptr ? *stats : local_stats;
  s = {};
  if (source.size() < 3) return {};
  const double n = static_cast<double>(source.size());
  const double d2 = o.inlier_distance_m * o.inlier_distance_m;

  std::vector<Hypothesis> pool;
  tbb::task_arena arena(o.threads);  // TBB: no idle workers left spinning after the search
  for (long round = 0; s.iterations < o.max_iterations; ++round) {
    std::vector<std::vector<Hypothesis>> block_pools(kBlocksPerRound);
    std::vector<int> scored(kBlocksPerRound, 0);
    const int per_block =
        std::min<long>(kBlockIterations,
                       (o.max_iterations - s.iterations + kBlocksPerRound - 1) / kBlocksPerRound);
    arena.execute([&] {
      tbb::parallel_for(
          0, kBlocksPerRound,
          [&](int b) {
            searchBlock(source, target, o, round * kBlocksPerRound + b, per_block, &block_pools[b],
                        &scored[b]);
          },
          tbb::simple_partitioner());
    });
    for (int b = 0; b < kBlocksPerRound; ++b) {
      for (const Hypothesis& h : block_pools[b]) addToPool(h, o, &pool);
      s.hypotheses += scored[b];
    }
    s.iterations += per_block * kBlocksPerRound;
    if (pool.empty()) continue;
    // Draws needed to have met the best pose's inliers three at a time with `confidence`.
    const double w = std::min(1.0, pool.front().support / n);
    const double p_all_inliers = w * w * w;
    if (p_all_inliers >= 1.0) break;
    const double needed = std::log(1.0 - o.confidence) / std::log(1.0 - p_all_inliers);
    if (s.iterations >= needed) break;
  }

  // Each kept hypothesis refined on its own inliers, then the distinct ones best first.
  std::vector<Hypothesis> refined;
  for (Hypothesis h : pool) {
    for (int k = 0; k < kRefinements; ++k) {
      std::vector<int> inliers;
      for (size_t i = 0; i < source.size(); ++i) {
        if ((h.R * source[i] + h.t - target[i]).squaredNorm() < d2) {
          inliers.push_back(static_cast<int>(i));
        }
      }
      if (inliers.size() < 3) break;
      Hypothesis next = h;
      fitRigid(source, target, inliers, &next);
      next.support = support(next, source, target, d2);
      if (!next.R.allFinite() || next.support < h.support) break;
      h = next;
    }
    addToPool(h, o, &refined);
  }
  std::vector<RigidCandidate> out;
  for (const Hypothesis& h : refined) {
    if (static_cast<int>(out.size()) == o.max_candidates) break;
    if (h.support < 3 || h.support < o.rival_support * refined.front().support) break;
    out.push_back({SE3Quat(h.R, h.t), h.support});
  }
  return out;
}

}  // namespace pnpba
