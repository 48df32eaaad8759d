// The native LM's path for two-view graphs (internal): one free VertexSE3Expmap, any number of
// fixed ones, free marginalised VertexPointXYZ points each observed exactly once by the free
// pose, and only EdgeProjectXYZ2UV / EdgeSE3ProjectXYZ edges (the library's own types) with an
// information w I and no robust kernel: the textbook's graphs, with or without camera 1.
//
// The same normal equations and steps as the general path (native_levenberg.h), computed per
// point in one vector lane (two_view_loops.h) instead of per edge object, and with the points
// eliminated in the free camera's frame. There a point's observation gives M = w AᵀA and
// g = -w Aᵀ e (A = de/dP) and the pose Jacobian is A Q with Q = [-[P]x | I], so
//   H_pp = sum Qᵀ M Q,  H_pl = Qᵀ M R,  R H_ll Rᵀ = M + R F Rᵀ =: H2  (F: the fixed cameras'
//   terms in the world frame),  H_pl (H_ll + lambda I)^-1 H_plᵀ = Qᵀ M (H2 + lambda I)^-1 M Q,
// and S = lambda I + sum Qᵀ (M - M N^-1 M) Q with N = H2 + lambda I: 3 x 3 products per point
// where the general path forms 6 x 3 and 6 x 6 ones. The results agree with the general path to
// round-off (tests/optimize/two_view_kernel_test.cpp); OptimizerOptions::two_view_kernel turns it
// off.
#pragma once

#include <cstddef>
#include <utility>
#include <vector>

#include "pnpba/optimize/optimizable_graph.h"
#include "two_view_loops.h"

namespace pnpba {

class TwoViewKernel {
 public:
  // free_vertices: the solver's free vertices, its num_poses poses first. True when the active
  // graph is a two-view graph (above) and the kernel has taken it; false otherwise.
  bool build(const std::vector<Vertex*>& free_vertices, size_t num_poses,
             const std::vector<Edge*>& edges);
  // Every edge's error at the current estimates (written into the edges) and what the normal
  // equations need of it; returns the sum of the edges' chi2.
  double evaluate();
  // The normal equations at the last evaluate(): the pose's gradient bp (6) and the points'
  // world-frame gradients bl (3 per point, in the solver's landmark order).
  void assemble(double* bp, double* bl);
  // The largest diagonal entry of H_pp and every H_ll (g2o's first damping is tau times it).
  double maxDiagonal() const;
  // S (6 x 6 column-major, lower triangle) and its right-hand side at damping lambda.
  void eliminate(double lambda, double* S, double* rhs);
  // The points' world-frame steps (3 per point) from the pose's step xp.
  void backSubstitute(const double* xp, double* xl);

 private:
  // The constants of n observations, one per lane.
  struct Constants {
    std::vector<double> mu, mv, fx, fy, cx, cy, w;
    void resize(size_t n);
  };
  // What an evaluation gives per point: its free observation's P, e, M, g, and the fixed
  // cameras' world-frame sums F (6) and f (3). Two sets, so that a rejected trial does not
  // overwrite the system being solved.
  struct PointTerms {
    std::vector<double> data;
    double *p[3], *e[2], *m[6], *g[3], *F[6], *f[3];
    void resize(size_t n);
  };

  bool accept(Edge* e, size_t num_poses, Constants* c, size_t i);
  two_view::ObservationArrays observations(const Constants& c, size_t begin, size_t end,
                                           const double* x, const double* y, const double* z,
                                           double* const p[3], double* const e[2],
                                           double* const m[6], double* const g[3]) const;
  two_view::PointArrays points() const;
  void writeErrors();

  Vertex* pose_ = nullptr;
  std::vector<Vertex*> points_;
  std::vector<Edge*> free_edges_;  // the free pose's edge of each point
  Constants free_;
  // Observations by fixed cameras, grouped by camera: [group_begin_[k], group_begin_[k + 1]).
  std::vector<Edge*> fixed_edges_;
  std::vector<int> fixed_point_;
  Constants fixed_;
  std::vector<size_t> group_begin_;
  std::vector<two_view::CameraPose> group_camera_;

  std::vector<double> x_, y_, z_;     // the points, gathered per evaluation
  std::vector<double> fixed_buffer_;  // the fixed observations' per-lane terms
  double *fx_[3], *fp_[3], *fe_[2], *fm_[6], *fg_[3], *fh_[6], *fb_[3];
  PointTerms trial_, system_;
  bool trial_fresh_ = false;
  two_view::CameraPose trial_camera_{}, system_camera_{};
  // 6, 3, 6 and two_view::kEliminationTerms per point, lane-major.
  std::vector<double> h2_, b2_, ninv_, terms_;

  // The loops of the instruction set this CPU runs (two_view_loops.h).
  decltype(&two_view::evaluateObservations) evaluate_observations_ = nullptr;
  decltype(&two_view::rotateToWorld) rotate_to_world_ = nullptr;
  decltype(&two_view::assemble) assemble_ = nullptr;
  decltype(&two_view::maxDiagonal) max_diagonal_ = nullptr;
  decltype(&two_view::eliminate) eliminate_ = nullptr;
  decltype(&two_view::backSubstitute) back_substitute_ = nullptr;
};

}  // namespace pnpba
