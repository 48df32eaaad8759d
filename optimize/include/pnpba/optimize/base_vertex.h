// BaseVertex<D, T>: a vertex with a D-dimensional update and an estimate of type T (g2o's
// BaseVertex). Derived types implement oplusImpl, setToOriginImpl and the block view.
#pragma once

#include <vector>

#include "pnpba/optimize/optimizable_graph.h"

namespace pnpba {

template <int D, typename T>
class BaseVertex : public Vertex {
 public:
  static constexpr int Dimension = D;
  using EstimateType = T;

  const T& estimate() const { return estimate_; }
  void setEstimate(const T& estimate) { estimate_ = estimate; }
  int dimension() const override { return D; }

  void push() override { backup_.push_back(estimate_); }
  void pop() override {
    estimate_ = backup_.back();
    backup_.pop_back();
  }
  void discardTop() override { backup_.pop_back(); }

 protected:
  T estimate_{};

 private:
  std::vector<T> backup_;
};

}  // namespace pnpba
