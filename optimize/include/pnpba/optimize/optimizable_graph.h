// The type-erased pieces of a graph, mirroring g2o's OptimizableGraph: Vertex, Edge and
// Parameter. Concrete types derive from BaseVertex / BaseUnaryEdge / BaseBinaryEdge.
//
// Besides g2o's interface, every vertex exposes its estimate as a flat "parameter block"
// (blockSize() doubles, e.g. [qx qy qz qw tx ty tz] for a pose) and its update rule on that
// block (blockPlus), and every edge can evaluate itself at given blocks. That is all the
// Ceres back end needs, and it keeps Ceres out of this header.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "pnpba/optimize/robust_kernel.h"

namespace pnpba {

class SparseOptimizer;

// Where an edge accumulates a block of the normal equations: contiguous, column-major (so the
// edge's fixed-size products vectorise). Set by the solver; data == nullptr means "not in the
// system" (fixed or inactive vertex).
struct HessianSlot {
  double* data = nullptr;
};

class Parameter {
 public:
  virtual ~Parameter() = default;
  int id() const { return id_; }
  void setId(int id) { id_ = id; }

 private:
  int id_ = -1;
};

class Vertex {
 public:
  virtual ~Vertex() = default;

  int id() const { return id_; }
  void setId(int id) { id_ = id; }
  bool fixed() const { return fixed_; }
  void setFixed(bool fixed) { fixed_ = fixed; }
  // Marginalised vertices are eliminated by the Schur complement (points in BA).
  bool marginalized() const { return marginalized_; }
  void setMarginalized(bool marginalized) { marginalized_ = marginalized; }

  // Degrees of freedom of the update (the tangent space).
  virtual int dimension() const = 0;
  // g2o's update: estimate <- estimate [+] delta, delta has dimension() entries.
  void oplus(const double* delta) { oplusImpl(delta); }
  virtual void setToOriginImpl() = 0;

  // Parameter-block view of the estimate, for solvers.
  virtual int blockSize() const = 0;
  virtual void getBlock(double* x) const = 0;
  virtual void setBlock(const double* x) = 0;
  // x_plus = x [+] delta on blocks: the same rule as oplusImpl.
  virtual void blockPlus(const double* x, const double* delta, double* x_plus) const = 0;
  virtual bool estimateIsFinite() const = 0;

  // Backup stack, used by LM to undo rejected steps (g2o's push/pop/discardTop).
  virtual void push() = 0;
  virtual void pop() = 0;
  virtual void discardTop() = 0;

  // Solver bookkeeping: index in the system (-1 when not in it) and the slots edges write to.
  int hessianIndex() const { return hessian_index_; }
  void setHessianIndex(int index) { hessian_index_ = index; }
  HessianSlot& hessianSlot() { return hessian_slot_; }
  double* bData() const { return b_data_; }
  void setBData(double* b) { b_data_ = b; }

  // The optimizer that owns the vertex (g2o's graph()); null before addVertex.
  const SparseOptimizer* graph() const { return graph_; }

 protected:
  virtual void oplusImpl(const double* delta) = 0;

 private:
  friend class SparseOptimizer;  // sets graph_ when it takes ownership
  const SparseOptimizer* graph_ = nullptr;
  int id_ = -1;
  bool fixed_ = false;
  bool marginalized_ = false;
  int hessian_index_ = -1;
  HessianSlot hessian_slot_;
  double* b_data_ = nullptr;
};

class Edge {
 public:
  virtual ~Edge() = default;

  int id() const { return id_; }
  void setId(int id) { id_ = id; }
  // initializeOptimization(level) activates only the edges of that level (g2o semantics):
  // ORB-SLAM-style outlier rounds move rejected edges to level 1.
  int level() const { return level_; }
  void setLevel(int level) { level_ = level; }

  size_t numVertices() const { return num_vertices_; }
  Vertex* vertex(size_t i) const {
    if (i >= num_vertices_) throwNoVertexSlot(i);
    return vertices_[i];
  }
  void setVertex(size_t i, Vertex* v) {
    if (i >= num_vertices_) throwNoVertexSlot(i);
    vertices_[i] = v;
  }

  // Parameter slot `arg` refers to the parameter with id `parameter_id` in the optimiser.
  void setParameterId(int arg, int parameter_id);
  int parameterId(int arg) const;
  size_t numParameters() const { return num_parameters_; }
  // Called by the optimiser with the parameter for each slot; throws Error on a wrong type.
  virtual void resolveParameter(int arg, Parameter* p);

  // Takes ownership (as g2o does); nullptr removes the kernel.
  void setRobustKernel(RobustKernel* kernel) {
    kernel_.reset(kernel);
    weighted_chi2_ = -1;
  }
  RobustKernel* robustKernel() const { return kernel_.get(); }

  virtual int dimension() const = 0;
  virtual void computeError() = 0;
  virtual void linearizeOplus() = 0;
  // True when linearizeOplus() also leaves computeError()'s error: the native solver then
  // evaluates a trial step's errors and Jacobians in one pass, and an accepted step needs no
  // second linearisation.
  virtual bool linearizationUpdatesError() const { return false; }
  // The dimension() entries of the last computeError().
  virtual const double* errorData() const = 0;
  // e^T Omega e of the last computeError().
  virtual double chi2() const = 0;
  // rho(chi2()) with the robust kernel, chi2() without.
  double robustChi2() const;
  // rho'(chi2()), the weight g2o's first-order robust weighting puts on Omega (1 without a
  // kernel). The kernel's last evaluation is reused when chi2() is the one it was evaluated at:
  // the native solver asks for the weight right after robustChi2() at the same errors.
  double robustWeight() const;
  virtual bool measurementIsFinite() const = 0;
  // Adds this edge's J^T W J and -J^T W e to its vertices' slots, W = rho'(chi2) Omega.
  // Needs linearizeOplus() and computeError() at the current estimate.
  virtual void constructQuadraticForm() = 0;
  // Where the off-diagonal block between vertex 0 and 1 goes; transposed: the slot holds
  // block (1, 0) instead of (0, 1).
  void setOffDiagonalSlot(HessianSlot slot, bool transposed) {
    offdiag_slot_ = slot;
    offdiag_transposed_ = transposed;
  }

  // Ceres bridge: error and Jacobians at explicit parameter blocks (one per vertex, in the
  // layout of Vertex::getBlock), the state of the vertices untouched. Jacobians are w.r.t. each
  // vertex's tangent (dimension() columns), row-major; a null pointer means "not needed".
  virtual void evaluateAtBlocks(const double* const* blocks, double* error,
                                double* const* jacobians) const = 0;
  // Column-major dimension() x dimension() information matrix.
  virtual const double* informationData() const = 0;

 protected:
  // Unary and binary edges, at most two parameters: held in the edge itself, since a graph of
  // 150 edges otherwise spent a tenth of its solve allocating and freeing these lists.
  static constexpr size_t kMaxVertices = 2, kMaxParameters = 2;
  explicit Edge(size_t num_vertices);
  void resizeParameters(size_t n);

  HessianSlot offdiag_slot_;
  bool offdiag_transposed_ = false;

 private:
  int id_ = -1;
  int level_ = 0;
  [[noreturn]] void throwNoVertexSlot(size_t i) const;

  std::array<Vertex*, kMaxVertices> vertices_{};
  std::array<int, kMaxParameters> parameter_ids_{};
  size_t num_vertices_ = 0, num_parameters_ = 0;
  std::unique_ptr<RobustKernel> kernel_;
  // The chi2 the kernel was last evaluated at by robustChi2() (-1: none) and its rho'.
  mutable double weighted_chi2_ = -1, weight_ = 1;
};

}  // namespace pnpba
