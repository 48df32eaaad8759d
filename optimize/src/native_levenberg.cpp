#include "native_levenberg.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <thread>

#include "lm_damping.h"
#include "pnpba/core/cpu_features.h"
#include "pnpba/core/error.h"
#include "pnpba/optimize/sparse_optimizer.h"

namespace pnpba {

void NativeLevenberg::buildStructure(const std::vector<Vertex*>& active_vertices,
                                     const std::vector<Edge*>& active_edges) {
  vertices_.clear();
  edges_ = active_edges;
  pose_offset_.clear();
  pose_dim_.clear();
  landmarks_.clear();
  adjacency_.clear();
  pose_pose_blocks_.clear();
  pose_hdiag_.clear();
  all_pose6_landmark3_ = true;
  errors_current_ = false;
  jacobians_current_ = false;
  trial_linearizes_ = std::all_of(edges_.begin(), edges_.end(),
                                  [](const Edge* e) { return e->linearizationUpdatesError(); });

  const std::vector<Vertex*> landmark_vertices = orderVertices(active_vertices);
  allocateDiagonalBlocks(landmark_vertices);
  allocateOffDiagonalBlocks();
  two_view_ = use_two_view_ && all_pose6_landmark3_ && pose_pose_blocks_.empty() &&
              two_view_kernel_.build(vertices_, pose_offset_.size(), edges_);
}

std::vector<Vertex*> NativeLevenberg::orderVertices(const std::vector<Vertex*>& active_vertices) {
  for (Vertex* v : active_vertices) {
    v->setHessianIndex(-1);
    v->hessianSlot() = HessianSlot{};
    v->setBData(nullptr);
  }
  // Poses first, in id order (active_vertices is sorted by id).
  num_pose_dims_ = 0;
  vertices_.reserve(active_vertices.size());
  landmarks_.reserve(active_vertices.size());
  for (Vertex* v : active_vertices) {
    if (v->fixed() || v->marginalized()) continue;
    v->setHessianIndex(static_cast<int>(pose_offset_.size()));
    pose_offset_.push_back(num_pose_dims_);
    pose_dim_.push_back(v->dimension());
    all_pose6_landmark3_ &= v->dimension() == 6;
    num_pose_dims_ += v->dimension();
    vertices_.push_back(v);
  }
  std::vector<Vertex*> landmark_vertices;
  landmark_vertices.reserve(active_vertices.size());
  size_t hll_size = 0, bl_size = 0;
  for (Vertex* v : active_vertices) {
    if (v->fixed() || !v->marginalized()) continue;
    Landmark l;
    l.dim = v->dimension();
    l.hll = hll_size;
    l.bl = bl_size;
    hll_size += l.dim * l.dim;
    bl_size += l.dim;
    all_pose6_landmark3_ &= l.dim == 3;
    v->setHessianIndex(static_cast<int>(pose_offset_.size() + landmarks_.size()));
    landmarks_.push_back(l);
    landmark_vertices.push_back(v);
    vertices_.push_back(v);
  }
  return landmark_vertices;
}

// Diagonal blocks, gradient and solution vectors, and each vertex's pointers into them.
void NativeLevenberg::allocateDiagonalBlocks(const std::vector<Vertex*>& landmark_vertices) {
  size_t hll_size = 0, bl_size = 0;
  for (const Landmark& l : landmarks_) {
    hll_size += l.dim * l.dim;
    bl_size += l.dim;
  }
  size_t hdiag_size = 0;
  for (int d : pose_dim_) {
    pose_hdiag_.push_back(hdiag_size);
    hdiag_size += d * d;
  }
  hpp_diag_.assign(hdiag_size, 0.0);
  s_.resize(num_pose_dims_, num_pose_dims_);
  bp_.setZero(num_pose_dims_);
  rhs_.resize(num_pose_dims_);
  xp_.resize(num_pose_dims_);
  hll_.assign(hll_size, 0.0);
  dinv_.assign(hll_size, 0.0);
  bl_.assign(bl_size, 0.0);
  xl_.assign(bl_size, 0.0);

  const int num_poses = static_cast<int>(pose_offset_.size());
  for (int k = 0; k < num_poses; ++k) {
    vertices_[k]->hessianSlot() = HessianSlot{hpp_diag_.data() + pose_hdiag_[k]};
    vertices_[k]->setBData(bp_.data() + pose_offset_[k]);
  }
  for (size_t i = 0; i < landmarks_.size(); ++i) {
    Vertex* v = landmark_vertices[i];
    v->hessianSlot() = HessianSlot{hll_.data() + landmarks_[i].hll};
    v->setBData(bl_.data() + landmarks_[i].bl);
  }
}

void NativeLevenberg::allocateOffDiagonalBlocks() {
  const int num_poses = static_cast<int>(pose_offset_.size());
  // Off-diagonal blocks. Pose-landmark blocks are stored (pose_dim x landmark_dim), one per
  // (pose, landmark) pair however many edges share it; offsets are fixed before any pointer is
  // handed out because hpl_ is sized once.
  // (landmark, pose, offset) per pose-landmark block in edge order; a landmark has few poses, so
  // an existing block is found by scanning back over that landmark's own (linked) entries.
  struct PoseLandmarkBlock {
    int landmark, pose;
    size_t offset;
    int previous;  // the landmark's previous entry, -1 for none
  };
  std::vector<PoseLandmarkBlock> blocks;
  std::vector<int> last_block(landmarks_.size(), -1);
  size_t hpl_size = 0, off_size = 0;
  struct Pending {
    Edge* edge;
    size_t offset;
    bool transposed;
  };
  std::vector<Pending> pending, pending_pose_pose;
  blocks.reserve(edges_.size());
  pending.reserve(edges_.size());
  for (Edge* e : edges_) {
    e->setOffDiagonalSlot(HessianSlot{}, false);
    if (e->numVertices() != 2) continue;
    Vertex* a = e->vertex(0);
    Vertex* b = e->vertex(1);
    if (a->hessianIndex() < 0 || b->hessianIndex() < 0) continue;
    if (a == b)
      throw Error("edge " + std::to_string(e->id()) + ": both ends are vertex " +
                  std::to_string(a->id()));
    const bool a_land = a->marginalized(), b_land = b->marginalized();
    if (a_land && b_land) {
      throw Error("edge " + std::to_string(e->id()) + " joins two marginalized vertices (" +
                  std::to_string(a->id()) + ", " + std::to_string(b->id()) +
                  "); the Schur complement needs one end not marginalized");
    }
    if (!a_land && !b_land) {
      pose_pose_blocks_.push_back({a->hessianIndex(), b->hessianIndex(), off_size});
      pending_pose_pose.push_back({e, off_size, false});
      off_size += a->dimension() * b->dimension();
      continue;
    }
    Vertex* pose = a_land ? b : a;
    Vertex* land = a_land ? a : b;
    const int p = pose->hessianIndex();
    const int l = land->hessianIndex() - num_poses;
    int found = last_block[l];
    while (found >= 0 && blocks[found].pose != p) found = blocks[found].previous;
    if (found < 0) {
      blocks.push_back({l, p, hpl_size, last_block[l]});
      found = last_block[l] = static_cast<int>(blocks.size()) - 1;
      hpl_size += pose->dimension() * land->dimension();
    }
    // Block (pose, landmark) is (vertex 1, vertex 0) when vertex 0 is the landmark.
    pending.push_back({e, blocks[found].offset, a_land});
  }
  hpl_.assign(hpl_size, 0.0);
  hpp_off_.assign(off_size, 0.0);
  for (const Pending& p : pending) {
    p.edge->setOffDiagonalSlot(HessianSlot{hpl_.data() + p.offset}, p.transposed);
  }
  for (const Pending& p : pending_pose_pose) {
    p.edge->setOffDiagonalSlot(HessianSlot{hpp_off_.data() + p.offset}, false);
  }
  // Each landmark's blocks in the order they were first met, as the elimination sums them.
  std::vector<size_t> count(landmarks_.size() + 1, 0);
  for (const PoseLandmarkBlock& b : blocks) ++count[b.landmark + 1];
  for (size_t l = 0; l < landmarks_.size(); ++l) count[l + 1] += count[l];
  adjacency_.resize(blocks.size());
  for (size_t l = 0; l < landmarks_.size(); ++l) {
    landmarks_[l].adj_begin = count[l];
    landmarks_[l].adj_end = count[l + 1];
  }
  for (const PoseLandmarkBlock& b : blocks) adjacency_[count[b.landmark]++] = {b.pose, b.offset};
}

size_t NativeLevenberg::edgeThreads() const {
  return std::min<size_t>(std::max(1, threads_), edges_.size() / 256 + 1);
}

// Runs f(edge) for every edge, split over edgeThreads() threads. Only for work that touches
// nothing but the edge itself (errors, Jacobians): accumulation stays serial, in edge order, so
// the result is bit-identical for any thread count.
template <typename F>
void NativeLevenberg::forEachEdge(F f) {
  const size_t n = edges_.size();
  const size_t threads = edgeThreads();
  if (threads <= 1) {
    for (Edge* e : edges_) f(e);
    return;
  }
  std::vector<std::thread> workers;
  for (size_t t = 1; t < threads; ++t) {
    workers.emplace_back([&, t] {
      for (size_t i = n * t / threads; i < n * (t + 1) / threads; ++i) f(edges_[i]);
    });
  }
  for (size_t i = 0; i < n / threads; ++i) f(edges_[i]);
  for (std::thread& w : workers) w.join();
}

double NativeLevenberg::activeRobustChi2(bool linearize) {
  if (two_view_) return two_view_kernel_.evaluate();  // its errors come with their linearisation
  double chi2 = 0;
  if (edgeThreads() <= 1) {  // one pass, the edge still in cache for its chi2
    for (Edge* e : edges_) {
      linearize ? e->linearizeOplus() : e->computeError();
      chi2 += e->robustChi2();
    }
    return chi2;
  }
  if (linearize) {
    forEachEdge([](Edge* e) { e->linearizeOplus(); });
  } else {
    forEachEdge([](Edge* e) { e->computeError(); });
  }
  for (Edge* e : edges_) chi2 += e->robustChi2();
  return chi2;
}

void NativeLevenberg::buildSystem() {
  if (two_view_) {
    if (!jacobians_current_) two_view_kernel_.evaluate();
    jacobians_current_ = true;
    two_view_kernel_.assemble(bp_.data(), bl_.data());
    return;
  }
  std::fill(hpp_diag_.begin(), hpp_diag_.end(), 0.0);
  std::fill(hpp_off_.begin(), hpp_off_.end(), 0.0);
  bp_.setZero();
  std::fill(hll_.begin(), hll_.end(), 0.0);
  std::fill(bl_.begin(), bl_.end(), 0.0);
  std::fill(hpl_.begin(), hpl_.end(), 0.0);
  if (!jacobians_current_) forEachEdge([](Edge* e) { e->linearizeOplus(); });
  jacobians_current_ = true;
  for (Edge* e : edges_) e->constructQuadraticForm();
}

// Any vertex sizes (the 6/3 case has its own kernel, landmark_elimination.h).
void NativeLevenberg::eliminateLandmarks(double lambda) {
  for (const Landmark& l : landmarks_) {
    const int ld = l.dim;
    Eigen::MatrixXd A = Eigen::Map<const Eigen::MatrixXd>(hll_.data() + l.hll, ld, ld);
    A.diagonal().array() += lambda;
    Eigen::Map<Eigen::MatrixXd> D(dinv_.data() + l.hll, ld, ld);
    D = A.inverse();
    const Eigen::Map<const Eigen::VectorXd> b(bl_.data() + l.bl, ld);
    for (size_t i = l.adj_begin; i < l.adj_end; ++i) {
      const Adjacent& ai = adjacency_[i];
      const int pi = pose_dim_[ai.pose], oi = pose_offset_[ai.pose];
      const Eigen::Map<const Eigen::MatrixXd> Hi(hpl_.data() + ai.hpl, pi, ld);
      const Eigen::MatrixXd HiD = Hi * D;
      rhs_.segment(oi, pi).noalias() -= HiD * b;
      // The blocks on and below S's block diagonal: the Cholesky factorisation reads only the
      // lower triangle, so the blocks above it are left unwritten.
      for (size_t j = l.adj_begin; j < l.adj_end; ++j) {
        const Adjacent& aj = adjacency_[j];
        const int pj = pose_dim_[aj.pose], oj = pose_offset_[aj.pose];
        if (oj > oi) continue;
        const Eigen::Map<const Eigen::MatrixXd> Hj(hpl_.data() + aj.hpl, pj, ld);
        s_.block(oi, oj, pi, pj).noalias() -= HiD * Hj.transpose();
      }
    }
  }
}

void NativeLevenberg::backSubstitute() {
  for (const Landmark& l : landmarks_) {
    const int ld = l.dim;
    Eigen::VectorXd r = Eigen::Map<const Eigen::VectorXd>(bl_.data() + l.bl, ld);
    for (size_t i = l.adj_begin; i < l.adj_end; ++i) {
      const Adjacent& a = adjacency_[i];
      const Eigen::Map<const Eigen::MatrixXd> H(hpl_.data() + a.hpl, pose_dim_[a.pose], ld);
      r.noalias() -= H.transpose() * xp_.segment(pose_offset_[a.pose], pose_dim_[a.pose]);
    }
    Eigen::Map<Eigen::VectorXd>(xl_.data() + l.bl, ld) =
        Eigen::Map<const Eigen::MatrixXd>(dinv_.data() + l.hll, ld, ld) * r;
  }
}

bool NativeLevenberg::solveDamped(double lambda) {
  if (two_view_) {
    s_.setZero();
    two_view_kernel_.eliminate(lambda, s_.data(), rhs_.data());
    llt_.compute(s_);
    if (llt_.info() != Eigen::Success) return false;
    xp_ = llt_.solve(rhs_);
    two_view_kernel_.backSubstitute(xp_.data(), xl_.data());
    return finiteSteps();
  }
  // S = Hpp + lambda I, assembled from the blocks the edges wrote.
  s_.setZero();
  for (size_t k = 0; k < pose_offset_.size(); ++k) {
    const int o = pose_offset_[k], d = pose_dim_[k];
    s_.block(o, o, d, d) =
        Eigen::Map<const Eigen::MatrixXd>(hpp_diag_.data() + pose_hdiag_[k], d, d);
  }
  for (const PosePoseBlock& b : pose_pose_blocks_) {
    const int ro = pose_offset_[b.row_pose], rd = pose_dim_[b.row_pose];
    const int co = pose_offset_[b.col_pose], cd = pose_dim_[b.col_pose];
    const Eigen::Map<const Eigen::MatrixXd> B(hpp_off_.data() + b.offset, rd, cd);
    s_.block(ro, co, rd, cd) += B;
    s_.block(co, ro, cd, rd) += B.transpose();
  }
  s_.diagonal().array() += lambda;
  rhs_ = bp_;
  if (all_pose6_landmark3_) {
    (cpuHasAvx2Fma() ? avx2::eliminateLandmarks63 : eliminateLandmarks63)(
        landmarks_.data(), landmarks_.size(), adjacency_.data(), pose_offset_.data(), hll_.data(),
        bl_.data(), hpl_.data(), lambda, dinv_.data(), s_.data(), static_cast<int>(s_.rows()),
        rhs_.data());
  } else {
    eliminateLandmarks(lambda);
  }
  if (num_pose_dims_ > 0) {
    llt_.compute(s_);
    if (llt_.info() != Eigen::Success) return false;
    xp_ = llt_.solve(rhs_);
  }
  if (all_pose6_landmark3_) {
    (cpuHasAvx2Fma() ? avx2::backSubstitute63 : backSubstitute63)(
        landmarks_.data(), landmarks_.size(), adjacency_.data(), pose_offset_.data(), hpl_.data(),
        dinv_.data(), bl_.data(), xp_.data(), xl_.data());
  } else {
    backSubstitute();
  }
  return finiteSteps();
}

bool NativeLevenberg::finiteSteps() const {
  if (!xp_.allFinite()) return false;
  for (double x : xl_) {
    if (!std::isfinite(x)) return false;
  }
  return true;
}

bool NativeLevenberg::reducedCovariance(Eigen::MatrixXd* covariance) {
  activeRobustChi2();
  jacobians_current_ = false;  // the estimates may have changed since the last solve
  buildSystem();
  errors_current_ = true;
  if (num_pose_dims_ == 0 || !solveDamped(0.0)) return false;
  // llt_ holds the factor of S (solveDamped(0) formed it); check it is well conditioned.
  const Eigen::VectorXd d = llt_.matrixLLT().diagonal();
  if (!(d.minCoeff() > 1e-12 * d.maxCoeff())) return false;
  *covariance = llt_.solve(Eigen::MatrixXd::Identity(num_pose_dims_, num_pose_dims_));
  return covariance->allFinite();
}

// x^T (lambda x + b): the decrease of chi2 the damped linear model predicts (g2o's scale).
double NativeLevenberg::predictedReduction(double lambda) const {
  double scale = xp_.dot(lambda * xp_ + bp_);
  for (size_t i = 0; i < xl_.size(); ++i) scale += xl_[i] * (lambda * xl_[i] + bl_[i]);
  return scale;
}

void NativeLevenberg::applyUpdate() {
  size_t k = 0;
  for (; k < pose_offset_.size(); ++k) vertices_[k]->oplus(xp_.data() + pose_offset_[k]);
  for (size_t l = 0; l < landmarks_.size(); ++l, ++k) {
    vertices_[k]->oplus(xl_.data() + landmarks_[l].bl);
  }
}

NativeLevenberg::StepResult NativeLevenberg::iterate(bool first, const OptimizerOptions& options) {
  threads_ = options.num_threads;
  // g2o recomputes every error here; after an accepted step, or when the caller has just
  // computed them (setErrorsCurrent), they are already current.
  if (!errors_current_) current_chi2_ = activeRobustChi2();
  errors_current_ = true;
  buildSystem();
  if (first) {
    if (options.user_lambda_init > 0) {
      lambda_ = options.user_lambda_init;
    } else {
      double max_diag = two_view_ ? two_view_kernel_.maxDiagonal() : 0.0;
      for (size_t k = 0; k < pose_offset_.size() && !two_view_; ++k) {
        const int d = pose_dim_[k];
        for (int j = 0; j < d; ++j) {
          max_diag = std::max(max_diag, std::abs(hpp_diag_[pose_hdiag_[k] + j * d + j]));
        }
      }
      for (size_t l = 0; l < landmarks_.size() && !two_view_; ++l) {
        for (int d = 0; d < landmarks_[l].dim; ++d) {
          const size_t at = landmarks_[l].hll + d * landmarks_[l].dim + d;
          max_diag = std::max(max_diag, std::abs(hll_[at]));
        }
      }
      lambda_ = options.tau * max_diag;
    }
    nu_ = 2;
  }

  double rho = 0;
  bool converged = false;
  trials_ = 0;
  do {
    const bool ok = solveDamped(lambda_);
    const double predicted = ok ? predictedReduction(lambda_) : 0.0;
    if (ok && trials_ == 0 && predicted < min_predicted_decrease_) {
      return StepResult::kConverged;  // state untouched, errors still current
    }
    for (Vertex* v : vertices_) v->push();
    if (ok) applyUpdate();
    double new_chi2 = activeRobustChi2(trial_linearizes_);
    if (!ok) new_chi2 = std::numeric_limits<double>::max();
    const double scale = ok ? predicted + 1e-3 : 1.0;
    rho = (current_chi2_ - new_chi2) / scale;
    if (rho > 0 && std::isfinite(new_chi2)) {
      lambda_ = internal::acceptedStepLambda(lambda_, rho);
      nu_ = 2;
      // Near the minimum LM converges fast: after an accepted step that leaves this little to
      // gain (lm_damping.h), the next one would change nothing that matters, so it is skipped.
      converged = convergence_.convergedAfter(current_chi2_ - new_chi2);
      current_chi2_ = new_chi2;
      errors_current_ = true;
      jacobians_current_ = trial_linearizes_;  // linearised at the new estimates already
      for (Vertex* v : vertices_) v->discardTop();
    } else {
      lambda_ *= nu_;
      nu_ *= 2;
      for (Vertex* v : vertices_) v->pop();
      errors_current_ = false;  // they are those of the rejected trial
      jacobians_current_ = jacobians_current_ && !trial_linearizes_;  // ... and so are these
      if (!std::isfinite(lambda_)) break;
    }
    ++trials_;
  } while (rho < 0 && trials_ < options.max_trials_after_failure);

  if (trials_ == options.max_trials_after_failure || rho == 0 || !std::isfinite(lambda_)) {
    return StepResult::kTerminate;
  }
  return converged ? StepResult::kConverged : StepResult::kOk;
}

}  // namespace pnpba
