#include "pnpba/optimize/quadratic_form.h"

#include <Eigen/Core>

#include "pnpba/core/cpu_features.h"
#include "quadratic_form_kernels.h"

namespace pnpba::internal {

// BaseBinaryEdge's generic expressions, on these sizes.
void baseline::addPointQuadraticForm(double w, const double* J_p, const double* e, double* H_pp,
                                     double* b_p) {
  const Eigen::Map<const Eigen::Matrix<double, 2, 3>> Jp(J_p);
  const Eigen::Matrix<double, 3, 2> pW = w * Jp.transpose();
  Eigen::Map<Eigen::Matrix3d>(H_pp).noalias() += pW * Jp;
  Eigen::Map<Eigen::Vector3d>(b_p).noalias() -= pW * Eigen::Map<const Eigen::Vector2d>(e);
}

void baseline::addPointPoseQuadraticForm(double w, const double* J_p, const double* J_c,
                                         const double* e, double* H_pp, double* b_p, double* H_cc,
                                         double* b_c, double* H_cp) {
  addPointQuadraticForm(w, J_p, e, H_pp, b_p);
  const Eigen::Map<const Eigen::Matrix<double, 2, 6>> Jc(J_c);
  const Eigen::Matrix<double, 6, 2> cW = w * Jc.transpose();
  Eigen::Map<Eigen::Matrix<double, 6, 6>>(H_cc).noalias() += cW * Jc;
  Eigen::Map<Eigen::Matrix<double, 6, 1>>(b_c).noalias() -=
      cW * Eigen::Map<const Eigen::Vector2d>(e);
  Eigen::Map<Eigen::Matrix<double, 6, 3>>(H_cp).noalias() +=
      cW * Eigen::Map<const Eigen::Matrix<double, 2, 3>>(J_p);
}

namespace {

void resolvePointPose(double w, const double* J_p, const double* J_c, const double* e, double* H_pp,
                      double* b_p, double* H_cc, double* b_c, double* H_cp) {
  const PointPoseQuadraticForm kernel =
      cpuHasAvx2Fma() ? avx2::addPointPoseQuadraticForm : baseline::addPointPoseQuadraticForm;
  addPointPoseQuadraticForm.store(kernel, std::memory_order_relaxed);
  kernel(w, J_p, J_c, e, H_pp, b_p, H_cc, b_c, H_cp);
}

void resolvePoint(double w, const double* J_p, const double* e, double* H_pp, double* b_p) {
  const PointQuadraticForm kernel =
      cpuHasAvx2Fma() ? avx2::addPointQuadraticForm : baseline::addPointQuadraticForm;
  addPointQuadraticForm.store(kernel, std::memory_order_relaxed);
  kernel(w, J_p, e, H_pp, b_p);
}

}  // namespace

std::atomic<PointPoseQuadraticForm> addPointPoseQuadraticForm{resolvePointPose};
std::atomic<PointQuadraticForm> addPointQuadraticForm{resolvePoint};

}  // namespace pnpba::internal
