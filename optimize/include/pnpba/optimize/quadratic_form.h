// The normal-equation terms of the commonest edge (internal; BaseBinaryEdge): a 2-d error with
// an identity information matrix between a 3-d point (vertex 0) and a 6-dof pose (vertex 1). A
// third of a small graph's solve is spent forming them, so they are built twice, for the
// baseline instruction set and for AVX2 (quadratic_form_avx2.cpp), chosen at run time
// (cpuHasAvx2Fma). The AVX2 build fuses no multiply-add: each entry is the same products summed
// in the same order as Eigen's generic code, so both builds give the generic code's bits.
#pragma once

#include <atomic>

namespace pnpba::internal {

// With W = w I (column-major arrays; J_p 2 x 3, J_c 2 x 6, e 2):
// H_pp (3 x 3) += (w J_p)ᵀ J_p and b_p -= (w J_p)ᵀ e; H_cc (6 x 6) += (w J_c)ᵀ J_c,
// b_c -= (w J_c)ᵀ e and the pose-point block H_cp (6 x 3) += (w J_c)ᵀ J_p.
using PointPoseQuadraticForm = void (*)(double w, const double* J_p, const double* J_c,
                                        const double* e, double* H_pp, double* b_p, double* H_cc,
                                        double* b_c, double* H_cp);
// The point's terms alone (the pose fixed): H_pp and b_p as above.
using PointQuadraticForm = void (*)(double w, const double* J_p, const double* e, double* H_pp,
                                    double* b_p);
// This CPU's build, called through directly (a wrapper that chose on each call cost a tenth of
// the kernel). Each starts as a resolver, constant-initialised so that it can be called at any
// time, which on its first call puts this CPU's build in its place and runs it.
extern std::atomic<PointPoseQuadraticForm> addPointPoseQuadraticForm;
extern std::atomic<PointQuadraticForm> addPointQuadraticForm;

}  // namespace pnpba::internal
