// BaseUnaryEdge / BaseBinaryEdge: fixed-size edges in g2o's shape (error_, measurement_,
// information_, jacobianOplusXi_, jacobianOplusXj_). A concrete edge writes ONE function,
// evaluate(), giving the error and, on request, its Jacobians w.r.t. the vertices' tangents
// at given estimates. computeError(), linearizeOplus() (the native solver) and
// evaluateAtBlocks() (the Ceres bridge) are all built on it, so both solvers use the same maths.
//
// Error convention (DESIGN.md section 3): e = measurement - prediction; chi2 = e^T Omega e.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <type_traits>

#include "pnpba/optimize/optimizable_graph.h"
#include "pnpba/optimize/quadratic_form.h"

namespace pnpba {

template <int D, typename M>
class BaseEdge : public Edge {
 public:
  static constexpr int Dimension = D;
  using Measurement = M;
  using ErrorVector = Eigen::Matrix<double, D, 1>;
  using InformationType = Eigen::Matrix<double, D, D>;

  int dimension() const override { return D; }
  const M& measurement() const { return measurement_; }
  virtual void setMeasurement(const M& m) { measurement_ = m; }
  const ErrorVector& error() const { return error_; }
  // Writable, as g2o's: a solver that evaluates edges in batches stores their errors here.
  ErrorVector& error() { return error_; }
  const InformationType& information() const { return information_; }
  void setInformation(const InformationType& information) {
    information_ = information;
    information_is_identity_ = information == InformationType::Identity();
  }
  const double* informationData() const override { return information_.data(); }
  const double* errorData() const override { return error_.data(); }
  double chi2() const override { return error_.dot(information_ * error_); }
  bool measurementIsFinite() const override {
    return measurementFinite(measurement_) && information_.allFinite();
  }

 protected:
  explicit BaseEdge(size_t num_vertices) : Edge(num_vertices) {}
  // J^T W with W = rho'(chi2) Omega, skipping the product when Omega is the identity.
  template <typename Jacobian>
  Eigen::Matrix<double, Jacobian::ColsAtCompileTime, D> weightedTranspose(const Jacobian& J,
                                                                          double w) const {
    if (information_is_identity_) return w * J.transpose();
    return J.transpose() * (w * information_);
  }

  M measurement_{};
  ErrorVector error_ = ErrorVector::Zero();
  InformationType information_ = InformationType::Identity();
  bool information_is_identity_ = true;

 private:
  template <typename T>
  static bool measurementFinite(const T& m) {
    if constexpr (std::is_arithmetic_v<T>) {
      return std::isfinite(m);
    } else {
      return m.allFinite();
    }
  }
};

template <int D, typename M, typename VertexXi>
class BaseUnaryEdge : public BaseEdge<D, M> {
 public:
  using Base = BaseEdge<D, M>;
  using typename Base::ErrorVector;
  using JacobianXiType = Eigen::Matrix<double, D, VertexXi::Dimension>;

  BaseUnaryEdge() : Base(1) {}

  // Error at xi, and its Jacobian w.r.t. the tangent of xi when Ji != nullptr.
  virtual void evaluate(const typename VertexXi::EstimateType& xi, ErrorVector* error,
                        JacobianXiType* Ji) const = 0;

  void computeError() override { evaluate(vi()->estimate(), &this->error_, nullptr); }
  // The error and, for a free vertex, the Jacobian (a fixed vertex's is never read; g2o's
  // numeric linearizeOplus skips it too).
  void linearizeOplus() override {
    evaluate(vi()->estimate(), &this->error_, vi()->fixed() ? nullptr : &jacobianOplusXi_);
  }
  bool linearizationUpdatesError() const override { return true; }
  const JacobianXiType& jacobianOplusXi() const { return jacobianOplusXi_; }

  void constructQuadraticForm() override {
    HessianSlot& slot = vi()->hessianSlot();
    if (slot.data == nullptr) return;
    const Eigen::Matrix<double, VertexXi::Dimension, D> JtW =
        this->weightedTranspose(jacobianOplusXi_, this->robustWeight());
    Eigen::Map<Eigen::Matrix<double, VertexXi::Dimension, VertexXi::Dimension>> H(slot.data);
    H.noalias() += JtW * jacobianOplusXi_;
    Eigen::Map<Eigen::Matrix<double, VertexXi::Dimension, 1>> b(vi()->bData());
    b.noalias() -= JtW * this->error_;
  }

  void evaluateAtBlocks(const double* const* blocks, double* error,
                        double* const* jacobians) const override {
    const auto xi = VertexXi::estimateFromBlock(blocks[0]);
    ErrorVector e;
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      JacobianXiType J;
      evaluate(xi, &e, &J);
      Eigen::Map<Eigen::Matrix<double, D, VertexXi::Dimension, Eigen::RowMajor>> out(jacobians[0]);
      out = J;
    } else {
      evaluate(xi, &e, nullptr);
    }
    Eigen::Map<ErrorVector> error_out(error);
    error_out = e;
  }

 protected:
  VertexXi* vi() const { return static_cast<VertexXi*>(this->vertex(0)); }
  JacobianXiType jacobianOplusXi_ = JacobianXiType::Zero();
};

template <int D, typename M, typename VertexXi, typename VertexXj>
class BaseBinaryEdge : public BaseEdge<D, M> {
 public:
  using Base = BaseEdge<D, M>;
  using typename Base::ErrorVector;
  static constexpr int Di = VertexXi::Dimension;
  static constexpr int Dj = VertexXj::Dimension;
  using JacobianXiType = Eigen::Matrix<double, D, Di>;
  using JacobianXjType = Eigen::Matrix<double, D, Dj>;

  BaseBinaryEdge() : Base(2) {}

  // Error at (xi, xj); Jacobians w.r.t. the tangents of xi and xj when requested (non-null).
  virtual void evaluate(const typename VertexXi::EstimateType& xi,
                        const typename VertexXj::EstimateType& xj, ErrorVector* error,
                        JacobianXiType* Ji, JacobianXjType* Jj) const = 0;

  void computeError() override {
    evaluate(vi()->estimate(), vj()->estimate(), &this->error_, nullptr, nullptr);
  }
  // Only the free vertices' Jacobians (a fixed one's is never read; g2o's numeric
  // linearizeOplus skips it too): an edge to a fixed camera costs its point Jacobian alone.
  void linearizeOplus() override {
    evaluate(vi()->estimate(), vj()->estimate(), &this->error_,
             vi()->fixed() ? nullptr : &jacobianOplusXi_,
             vj()->fixed() ? nullptr : &jacobianOplusXj_);
  }
  bool linearizationUpdatesError() const override { return true; }
  const JacobianXiType& jacobianOplusXi() const { return jacobianOplusXi_; }
  const JacobianXjType& jacobianOplusXj() const { return jacobianOplusXj_; }

  void constructQuadraticForm() override {
    const HessianSlot& si = vi()->hessianSlot();
    const HessianSlot& sj = vj()->hessianSlot();
    const HessianSlot& so = this->offdiag_slot_;
    const double w = this->robustWeight();
    // A point and a pose with an identity information (the textbook's edge): the kernels of
    // quadratic_form.h, the same sums on wider vectors.
    if constexpr (D == 2 && Di == 3 && Dj == 6) {
      if (this->information_is_identity_ && si.data != nullptr) {
        if (sj.data == nullptr) {
          internal::addPointQuadraticForm.load(std::memory_order_relaxed)(
              w, jacobianOplusXi_.data(), this->error_.data(), si.data, vi()->bData());
          return;
        }
        if (so.data != nullptr && this->offdiag_transposed_) {
          internal::addPointPoseQuadraticForm.load(std::memory_order_relaxed)(
              w, jacobianOplusXi_.data(), jacobianOplusXj_.data(), this->error_.data(), si.data,
              vi()->bData(), sj.data, vj()->bData(), so.data);
          return;
        }
      }
    }
    if (si.data != nullptr) {
      const Eigen::Matrix<double, Di, D> JitW = this->weightedTranspose(jacobianOplusXi_, w);
      Eigen::Map<Eigen::Matrix<double, Di, Di>>(si.data).noalias() += JitW * jacobianOplusXi_;
      Eigen::Map<Eigen::Matrix<double, Di, 1>>(vi()->bData()).noalias() -= JitW * this->error_;
      if (sj.data != nullptr && so.data != nullptr && !this->offdiag_transposed_) {
        Eigen::Map<Eigen::Matrix<double, Di, Dj>>(so.data).noalias() += JitW * jacobianOplusXj_;
      }
    }
    if (sj.data != nullptr) {
      const Eigen::Matrix<double, Dj, D> JjtW = this->weightedTranspose(jacobianOplusXj_, w);
      Eigen::Map<Eigen::Matrix<double, Dj, Dj>>(sj.data).noalias() += JjtW * jacobianOplusXj_;
      Eigen::Map<Eigen::Matrix<double, Dj, 1>>(vj()->bData()).noalias() -= JjtW * this->error_;
      if (si.data != nullptr && so.data != nullptr && this->offdiag_transposed_) {
        Eigen::Map<Eigen::Matrix<double, Dj, Di>>(so.data).noalias() += JjtW * jacobianOplusXi_;
      }
    }
  }

  void evaluateAtBlocks(const double* const* blocks, double* error,
                        double* const* jacobians) const override {
    const auto xi = VertexXi::estimateFromBlock(blocks[0]);
    const auto xj = VertexXj::estimateFromBlock(blocks[1]);
    ErrorVector e;
    JacobianXiType Ji;
    JacobianXjType Jj;
    const bool want_i = jacobians != nullptr && jacobians[0] != nullptr;
    const bool want_j = jacobians != nullptr && jacobians[1] != nullptr;
    evaluate(xi, xj, &e, want_i ? &Ji : nullptr, want_j ? &Jj : nullptr);
    Eigen::Map<ErrorVector> error_out(error);
    error_out = e;
    if (want_i) {
      Eigen::Map<Eigen::Matrix<double, D, Di, Eigen::RowMajor>> out(jacobians[0]);
      out = Ji;
    }
    if (want_j) {
      Eigen::Map<Eigen::Matrix<double, D, Dj, Eigen::RowMajor>> out(jacobians[1]);
      out = Jj;
    }
  }

 protected:
  VertexXi* vi() const { return static_cast<VertexXi*>(this->vertex(0)); }
  VertexXj* vj() const { return static_cast<VertexXj*>(this->vertex(1)); }
  JacobianXiType jacobianOplusXi_ = JacobianXiType::Zero();
  JacobianXjType jacobianOplusXj_ = JacobianXjType::Zero();
};

}  // namespace pnpba
