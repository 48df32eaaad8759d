// The two builds of quadratic_form.h's kernels (private): the baseline, Eigen's generic
// expressions (quadratic_form.cpp), and AVX2 intrinsics (quadratic_form_avx2.cpp; call only
// where cpuHasAvx2Fma()). Same arguments as quadratic_form.h; both give the same bits.
#pragma once

namespace pnpba::internal {

namespace baseline {
void addPointPoseQuadraticForm(double w, const double* J_p, const double* J_c, const double* e,
                               double* H_pp, double* b_p, double* H_cc, double* b_c, double* H_cp);
void addPointQuadraticForm(double w, const double* J_p, const double* e, double* H_pp, double* b_p);
}  // namespace baseline

namespace avx2 {
void addPointPoseQuadraticForm(double w, const double* J_p, const double* J_c, const double* e,
                               double* H_pp, double* b_p, double* H_cc, double* b_c, double* H_cp);
void addPointQuadraticForm(double w, const double* J_p, const double* e, double* H_pp, double* b_p);
}  // namespace avx2

}  // namespace pnpba::internal
