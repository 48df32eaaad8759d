// The Ceres back end's adaptors (internal; Ceres stays out of public headers).
//
// Manifold choice: a vertex whose block is larger than its tangent (a pose: 7 numbers, 6 dof)
// gets a VertexManifold with Plus(x, delta) = the vertex's own update (exp(delta) * T for
// VertexSE3Expmap) and PlusJacobian = [I; 0]. EdgeCostFunction hands Ceres the ambient Jacobian
// [sqrt(Omega) J, 0], J being the edge's analytic tangent Jacobian, so the product Ceres forms,
// ambient * PlusJacobian, is exactly sqrt(Omega) J. (Ceres only ever uses that product in its
// solvers.) tests/optimize/ceres_bridge_test.cpp proves it against numeric differentiation of
// e(exp(delta) * T).
#pragma once

#include <ceres/ceres.h>

#include <Eigen/Core>
#include <vector>

#include "pnpba/optimize/optimizable_graph.h"

namespace pnpba::internal {

class VertexManifold : public ceres::Manifold {
 public:
  explicit VertexManifold(const Vertex* prototype)
      : prototype_(prototype), ambient_(prototype->blockSize()), tangent_(prototype->dimension()) {}
  int AmbientSize() const override { return ambient_; }
  int TangentSize() const override { return tangent_; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  bool PlusJacobian(const double* x, double* jacobian) const override;
  // Not needed by the LM solve; Ceres only calls it in diagnostics.
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  bool MinusJacobian(const double* x, double* jacobian) const override;

 private:
  const Vertex* prototype_;
  int ambient_, tangent_;
};

// Residual r = sqrt(Omega) e, so that |r|^2 = e^T Omega e = the edge's chi2.
class EdgeCostFunction : public ceres::CostFunction {
 public:
  // Bounds of the stack buffers in Evaluate (photometric edges: 16 residuals; BAL: 9 dof).
  static constexpr int kMaxResidualDim = 16;
  static constexpr int kMaxTangentDim = 9;
  static constexpr size_t kMaxVertices = 2;

  explicit EdgeCostFunction(const Edge* edge);
  bool Evaluate(const double* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  const Edge* edge_;
  Eigen::MatrixXd sqrt_information_;  // upper triangular L^T with Omega = L L^T
  std::vector<int> tangent_sizes_;
};

// g2o's robust kernel as a Ceres loss: both are functions of s = e^T Omega e.
class KernelLoss : public ceres::LossFunction {
 public:
  explicit KernelLoss(const RobustKernel* kernel) : kernel_(kernel) {}
  void Evaluate(double s, double rho[3]) const override;

 private:
  const RobustKernel* kernel_;
};

}  // namespace pnpba::internal
