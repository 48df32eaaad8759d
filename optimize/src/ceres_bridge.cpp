#include "ceres_bridge.h"

#include <Eigen/Cholesky>
#include <string>

#include "pnpba/core/error.h"

namespace pnpba::internal {

bool VertexManifold::Plus(const double* x, const double* delta, double* x_plus_delta) const {
  prototype_->blockPlus(x, delta, x_plus_delta);
  return true;
}

bool VertexManifold::PlusJacobian(const double*, double* jacobian) const {
  Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> J(
      jacobian, ambient_, tangent_);
  J.setZero();
  J.topRows(tangent_).setIdentity();
  return true;
}

bool VertexManifold::Minus(const double*, const double*, double*) const { return false; }

bool VertexManifold::MinusJacobian(const double*, double* jacobian) const {
  Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>> J(
      jacobian, tangent_, ambient_);
  J.setZero();
  J.leftCols(tangent_).setIdentity();
  return true;
}

EdgeCostFunction::EdgeCostFunction(const Edge* edge) : edge_(edge) {
  const int d = edge->dimension();
  if (d > kMaxResidualDim || edge->numVertices() > kMaxVertices) {
    throw Error("edge " + std::to_string(edge->id()) + ": too large for the Ceres bridge");
  }
  set_num_residuals(d);
  for (size_t i = 0; i < edge->numVertices(); ++i) {
    mutable_parameter_block_sizes()->push_back(edge->vertex(i)->blockSize());
    tangent_sizes_.push_back(edge->vertex(i)->dimension());
    if (tangent_sizes_.back() > kMaxTangentDim) {
      throw Error("vertex " + std::to_string(edge->vertex(i)->id()) +
                  ": too many dof for the Ceres bridge");
    }
  }
  const Eigen::Map<const Eigen::MatrixXd> omega(edge->informationData(), d, d);
  Eigen::LLT<Eigen::MatrixXd> llt(omega);
  if (llt.info() != Eigen::Success) {
    throw Error("edge " + std::to_string(edge->id()) +
                ": information matrix is not positive definite");
  }
  sqrt_information_ = llt.matrixU();
}

bool EdgeCostFunction::Evaluate(const double* const* parameters, double* residuals,
                                double** jacobians) const {
  // Stack buffers: Evaluate runs for every edge at every iteration, so no heap allocation.
  const int d = num_residuals();
  const size_t n = tangent_sizes_.size();
  double error[kMaxResidualDim];
  double tangent[kMaxVertices][kMaxResidualDim * kMaxTangentDim];
  double* tangent_ptrs[kMaxVertices] = {nullptr, nullptr};
  if (jacobians != nullptr) {
    for (size_t i = 0; i < n; ++i) tangent_ptrs[i] = jacobians[i] ? tangent[i] : nullptr;
  }
  edge_->evaluateAtBlocks(parameters, error, jacobians != nullptr ? tangent_ptrs : nullptr);
  const Eigen::Map<const Eigen::VectorXd> e(error, d);
  if (!e.allFinite()) return false;
  Eigen::Map<Eigen::VectorXd>(residuals, d).noalias() = sqrt_information_ * e;
  if (jacobians == nullptr) return true;
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  for (size_t i = 0; i < n; ++i) {
    if (jacobians[i] == nullptr) continue;
    const int ambient = parameter_block_sizes()[i];
    Eigen::Map<RowMajor> J(jacobians[i], d, ambient);
    J.rightCols(ambient - tangent_sizes_[i]).setZero();
    J.leftCols(tangent_sizes_[i]).noalias() =
        sqrt_information_ * Eigen::Map<const RowMajor>(tangent[i], d, tangent_sizes_[i]);
  }
  return true;
}

void KernelLoss::Evaluate(double s, double rho[3]) const {
  Eigen::Vector3d r;
  kernel_->robustify(s, r);
  rho[0] = r[0];
  rho[1] = r[1];
  rho[2] = r[2];
}

}  // namespace pnpba::internal
