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

  // A stack of saved estimates. LM saves one level per trial, so the top lives in the vertex
  // and only deeper levels reach the heap: a solve then allocates nothing per vertex.
  void push() override {
    if (has_top_) deeper_.push_back(top_);
    top_ = estimate_;
    has_top_ = true;
  }
  void pop() override {
    estimate_ = top_;
    discardTop();
  }
  void discardTop() override {
    if (deeper_.empty()) {
      has_top_ = false;
      return;
    }
    top_ = deeper_.back();
    deeper_.pop_back();
  }

 protected:
  T estimate_{};

 private:
  T top_{};
  bool has_top_ = false;
  std::vector<T> deeper_;
};

}  // namespace pnpba
