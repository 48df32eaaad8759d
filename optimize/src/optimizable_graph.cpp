// Out-of-line parts of the Edge base class.
#include "pnpba/optimize/optimizable_graph.h"

#include <Eigen/Core>
#include <string>

#include "pnpba/core/error.h"

namespace pnpba {

void Edge::setParameterId(int arg, int parameter_id) {
  if (arg < 0 || static_cast<size_t>(arg) >= parameter_ids_.size()) {
    throw Error("edge " + std::to_string(id_) + ": has no parameter slot " + std::to_string(arg));
  }
  parameter_ids_[arg] = parameter_id;
}

void Edge::resolveParameter(int arg, Parameter*) {
  throw Error("edge " + std::to_string(id_) + ": has no parameter slot " + std::to_string(arg));
}

double Edge::robustChi2() const {
  if (!kernel_) return chi2();
  Eigen::Vector3d rho;
  kernel_->robustify(chi2(), rho);
  return rho[0];
}

}  // namespace pnpba
