// Out-of-line parts of the Edge base class.
#include "pnpba/optimize/optimizable_graph.h"

#include <Eigen/Core>
#include <string>

#include "pnpba/core/error.h"

namespace pnpba {

Edge::Edge(size_t num_vertices) : num_vertices_(num_vertices) {
  if (num_vertices > kMaxVertices) {
    throw Error("an edge joins at most " + std::to_string(kMaxVertices) + " vertices, not " +
                std::to_string(num_vertices));
  }
}

void Edge::resizeParameters(size_t n) {
  if (n > kMaxParameters) {
    throw Error("an edge has at most " + std::to_string(kMaxParameters) + " parameters, not " +
                std::to_string(n));
  }
  num_parameters_ = n;
  parameter_ids_.fill(-1);
}

void Edge::throwNoVertexSlot(size_t i) const {
  throw Error("edge " + std::to_string(id_) + ": has no vertex slot " + std::to_string(i));
}

int Edge::parameterId(int arg) const {
  if (arg < 0 || static_cast<size_t>(arg) >= num_parameters_) {
    throw Error("edge " + std::to_string(id_) + ": has no parameter slot " + std::to_string(arg));
  }
  return parameter_ids_[arg];
}

void Edge::setParameterId(int arg, int parameter_id) {
  if (arg < 0 || static_cast<size_t>(arg) >= num_parameters_) {
    throw Error("edge " + std::to_string(id_) + ": has no parameter slot " + std::to_string(arg));
  }
  parameter_ids_[arg] = parameter_id;
}

void Edge::resolveParameter(int arg, Parameter*) {
  throw Error("edge " + std::to_string(id_) + ": has no parameter slot " + std::to_string(arg));
}

double Edge::robustChi2() const {
  if (!kernel_) return chi2();
  const double e2 = chi2();
  Eigen::Vector3d rho;
  kernel_->robustify(e2, rho);
  weighted_chi2_ = e2, weight_ = rho[1];
  return rho[0];
}

double Edge::robustWeight() const {
  if (!kernel_) return 1.0;
  const double e2 = chi2();
  if (e2 == weighted_chi2_) return weight_;
  Eigen::Vector3d rho;
  kernel_->robustify(e2, rho);
  return rho[1];
}

}  // namespace pnpba
