#include "two_view_kernel.h"

#include <algorithm>
#include <typeinfo>

#include "pnpba/core/cpu_features.h"
#include "pnpba/optimize/edge_project_xyz2uv.h"
#include "pnpba/optimize/edge_se3_project_xyz.h"
#include "two_view_camera.h"

namespace pnpba {

namespace {

using PixelEdge = BaseBinaryEdge<2, Eigen::Vector2d, VertexPointXYZ, VertexSE3Expmap>;

bool isPose(const Vertex* v) { return typeid(*v) == typeid(VertexSE3Expmap); }
bool isPoint(const Vertex* v) { return typeid(*v) == typeid(VertexPointXYZ); }

const SE3Quat& poseOf(const Vertex* v) {
  return static_cast<const VertexSE3Expmap*>(v)->estimate();
}

}  // namespace

void TwoViewKernel::Constants::resize(size_t n) {
  for (std::vector<double>* v : {&mu, &mv, &fx, &fy, &cx, &cy, &w}) v->assign(n, 0.0);
}

void TwoViewKernel::PointTerms::resize(size_t n) {
  data.assign(23 * n, 0.0);
  double* next = data.data();
  for (double** slots : {p, g, f}) {
    for (int k = 0; k < 3; ++k, next += n) slots[k] = next;
  }
  for (int k = 0; k < 2; ++k, next += n) e[k] = next;
  for (int k = 0; k < 6; ++k, next += n) m[k] = next;
  for (int k = 0; k < 6; ++k, next += n) F[k] = next;
}

// An edge of the kind the kernel computes: its constants into c at lane i. False for any other.
bool TwoViewKernel::accept(Edge* e, size_t num_poses, Constants* c, size_t i) {
  if (e->robustKernel() != nullptr) return false;
  double fx, fy, cx, cy;
  if (typeid(*e) == typeid(EdgeProjectXYZ2UV)) {
    const CameraParameters* k = static_cast<const EdgeProjectXYZ2UV*>(e)->camera();
    if (k == nullptr) return false;
    fx = fy = k->focal_length;
    cx = k->principle_point.x(), cy = k->principle_point.y();
  } else if (typeid(*e) == typeid(EdgeSE3ProjectXYZ)) {
    const auto* s = static_cast<const EdgeSE3ProjectXYZ*>(e);
    fx = s->fx, fy = s->fy, cx = s->cx, cy = s->cy;
  } else {
    return false;
  }
  const Vertex* point = e->vertex(0);
  const Vertex* camera = e->vertex(1);
  if (point == nullptr || camera == nullptr || !isPoint(point) || !isPose(camera) ||
      point->fixed() || point->hessianIndex() < static_cast<int>(num_poses)) {
    return false;
  }
  const double* info = e->informationData();  // column-major 2 x 2
  if (!(info[0] > 0) || info[3] != info[0] || info[1] != 0 || info[2] != 0) return false;
  const auto* pixel = static_cast<const PixelEdge*>(e);
  c->mu[i] = pixel->measurement().x(), c->mv[i] = pixel->measurement().y();
  c->fx[i] = fx, c->fy[i] = fy, c->cx[i] = cx, c->cy[i] = cy, c->w[i] = info[0];
  return true;
}

bool TwoViewKernel::build(const std::vector<Vertex*>& free_vertices, size_t num_poses,
                          const std::vector<Edge*>& edges) {
  if (num_poses != 1 || free_vertices.empty() || !isPose(free_vertices[0])) return false;
  pose_ = free_vertices[0];
  points_.assign(free_vertices.begin() + 1, free_vertices.end());
  const size_t n = points_.size();
  if (n == 0) return false;
  for (const Vertex* v : points_) {
    if (!isPoint(v)) return false;
  }
  free_.resize(n);
  free_edges_.assign(n, nullptr);
  // Fixed cameras' edges in edge order first, then grouped by camera below.
  std::vector<Edge*> fixed;
  for (Edge* e : edges) {
    if (e->numVertices() != 2) return false;
    const Vertex* camera = e->vertex(1);
    if (camera != pose_) {
      fixed.push_back(e);
      continue;
    }
    const int index = e->vertex(0) == nullptr ? -1 : e->vertex(0)->hessianIndex();
    const size_t i = static_cast<size_t>(index) - num_poses;
    if (index < static_cast<int>(num_poses) || i >= n) return false;
    if (free_edges_[i] != nullptr) return false;  // one free observation per point
    if (!accept(e, num_poses, &free_, i)) return false;
    free_edges_[i] = e;
  }
  if (std::find(free_edges_.begin(), free_edges_.end(), nullptr) != free_edges_.end()) {
    return false;
  }
  std::stable_sort(fixed.begin(), fixed.end(),
                   [](const Edge* a, const Edge* b) { return a->vertex(1) < b->vertex(1); });
  const size_t nf = fixed.size();
  fixed_.resize(nf);
  fixed_edges_ = fixed;
  fixed_point_.assign(nf, 0);
  group_begin_.clear();
  group_camera_.clear();
  for (size_t j = 0; j < nf; ++j) {
    Edge* e = fixed[j];
    if (!accept(e, num_poses, &fixed_, j) || !e->vertex(1)->fixed()) return false;
    fixed_point_[j] = e->vertex(0)->hessianIndex() - static_cast<int>(num_poses);
    if (j == 0 || e->vertex(1) != fixed[j - 1]->vertex(1)) {
      group_begin_.push_back(j);
      group_camera_.push_back(cameraPoseOf(poseOf(e->vertex(1))));
    }
  }
  group_begin_.push_back(nf);

  x_.assign(n, 0.0), y_.assign(n, 0.0), z_.assign(n, 0.0);
  fixed_buffer_.assign(26 * nf, 0.0);
  double* next = fixed_buffer_.data();
  for (double** slots : {fx_, fp_, fg_, fb_}) {
    for (int k = 0; k < 3; ++k, next += nf) slots[k] = next;
  }
  for (int k = 0; k < 2; ++k, next += nf) fe_[k] = next;
  for (int k = 0; k < 6; ++k, next += nf) fm_[k] = next;
  for (int k = 0; k < 6; ++k, next += nf) fh_[k] = next;
  trial_.resize(n);
  system_.resize(n);
  trial_fresh_ = false;
  h2_.assign(6 * n, 0.0), b2_.assign(3 * n, 0.0), ninv_.assign(6 * n, 0.0);
  terms_.assign(two_view::kEliminationTerms * n, 0.0);

  const bool avx2 = cpuHasAvx2Fma();
  evaluate_observations_ =
      avx2 ? two_view::avx2::evaluateObservations : two_view::evaluateObservations;
  rotate_to_world_ = avx2 ? two_view::avx2::rotateToWorld : two_view::rotateToWorld;
  assemble_ = avx2 ? two_view::avx2::assemble : two_view::assemble;
  max_diagonal_ = avx2 ? two_view::avx2::maxDiagonal : two_view::maxDiagonal;
  eliminate_ = avx2 ? two_view::avx2::eliminate : two_view::eliminate;
  back_substitute_ = avx2 ? two_view::avx2::backSubstitute : two_view::backSubstitute;
  return true;
}

two_view::ObservationArrays TwoViewKernel::observations(
    const Constants& c, size_t begin, size_t end, const double* x, const double* y, const double* z,
    double* const p[3], double* const e[2], double* const m[6], double* const g[3]) const {
  two_view::ObservationArrays o;
  o.n = end - begin;
  o.x = x + begin, o.y = y + begin, o.z = z + begin;
  o.mu = c.mu.data() + begin, o.mv = c.mv.data() + begin;
  o.fx = c.fx.data() + begin, o.fy = c.fy.data() + begin;
  o.cx = c.cx.data() + begin, o.cy = c.cy.data() + begin, o.w = c.w.data() + begin;
  o.p0 = p[0] + begin, o.p1 = p[1] + begin, o.p2 = p[2] + begin;
  o.eu = e[0] + begin, o.ev = e[1] + begin;
  for (int k = 0; k < 6; ++k) o.m[k] = m[k] + begin;
  for (int k = 0; k < 3; ++k) o.g[k] = g[k] + begin;
  return o;
}

double TwoViewKernel::evaluate() {
  const size_t n = points_.size(), nf = fixed_edges_.size();
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d& X = static_cast<const VertexPointXYZ*>(points_[i])->estimate();
    x_[i] = X.x(), y_[i] = X.y(), z_[i] = X.z();
  }
  trial_camera_ = cameraPoseOf(poseOf(pose_));
  double chi2 = evaluate_observations_(
      trial_camera_, observations(free_, 0, n, x_.data(), y_.data(), z_.data(), trial_.p, trial_.e,
                                  trial_.m, trial_.g));

  for (size_t j = 0; j < nf; ++j) {
    const size_t i = static_cast<size_t>(fixed_point_[j]);
    fx_[0][j] = x_[i], fx_[1][j] = y_[i], fx_[2][j] = z_[i];
  }
  for (size_t k = 0; k + 1 < group_begin_.size(); ++k) {
    const size_t begin = group_begin_[k], end = group_begin_[k + 1];
    chi2 += evaluate_observations_(
        group_camera_[k],
        observations(fixed_, begin, end, fx_[0], fx_[1], fx_[2], fp_, fe_, fm_, fg_));
    double* m[6];
    double* g[3];
    double* h[6];
    double* b[3];
    for (int c = 0; c < 6; ++c) m[c] = fm_[c] + begin;
    for (int c = 0; c < 3; ++c) g[c] = fg_[c] + begin, b[c] = fb_[c] + begin;
    for (int c = 0; c < 6; ++c) h[c] = fh_[c] + begin;
    rotate_to_world_(group_camera_[k], end - begin, m, g, h, b);
  }
  for (int c = 0; c < 6; ++c) std::fill(trial_.F[c], trial_.F[c] + n, 0.0);
  for (int c = 0; c < 3; ++c) std::fill(trial_.f[c], trial_.f[c] + n, 0.0);
  for (size_t j = 0; j < nf; ++j) {
    const size_t i = static_cast<size_t>(fixed_point_[j]);
    for (int c = 0; c < 6; ++c) trial_.F[c][i] += fh_[c][j];
    for (int c = 0; c < 3; ++c) trial_.f[c][i] += fb_[c][j];
  }
  writeErrors();
  trial_fresh_ = true;
  return chi2;
}

// The edges keep their errors current, as the general path's computeError() leaves them.
void TwoViewKernel::writeErrors() {
  for (size_t i = 0; i < free_edges_.size(); ++i) {
    static_cast<PixelEdge*>(free_edges_[i])->error() << trial_.e[0][i], trial_.e[1][i];
  }
  for (size_t j = 0; j < fixed_edges_.size(); ++j) {
    static_cast<PixelEdge*>(fixed_edges_[j])->error() << fe_[0][j], fe_[1][j];
  }
}

two_view::PointArrays TwoViewKernel::points() const {
  two_view::PointArrays a;
  const size_t n = points_.size();
  a.n = n;
  for (int k = 0; k < 3; ++k) {
    a.p[k] = system_.p[k], a.g[k] = system_.g[k], a.f[k] = system_.f[k];
    a.b2[k] = const_cast<double*>(b2_.data()) + k * n;
  }
  for (int k = 0; k < 6; ++k) a.m[k] = system_.m[k];
  a.terms = const_cast<double*>(terms_.data());
  for (int k = 0; k < 6; ++k) {
    a.F[k] = system_.F[k];
    a.h2[k] = const_cast<double*>(h2_.data()) + k * n;
    a.ninv[k] = const_cast<double*>(ninv_.data()) + k * n;
  }
  return a;
}

void TwoViewKernel::assemble(double* bp, double* bl) {
  if (trial_fresh_) {
    std::swap(trial_, system_);
    system_camera_ = trial_camera_;
    trial_fresh_ = false;
  }
  assemble_(system_camera_, points(), bl, bp);
}

double TwoViewKernel::maxDiagonal() const { return max_diagonal_(system_camera_, points()); }

void TwoViewKernel::eliminate(double lambda, double* S, double* rhs) {
  eliminate_(points(), lambda, S, rhs);
}

void TwoViewKernel::backSubstitute(const double* xp, double* xl) {
  back_substitute_(system_camera_, points(), xp, xl);
}

}  // namespace pnpba
