#include "dense_cholesky.h"

#include <Eigen/Cholesky>

namespace pnpba::bal_detail {

namespace {
#include "dense_cholesky_impl.h"
}  // namespace

bool solveDenseSpd(double* upper, int n, double* rhs) {
  return solveDenseSpdImpl(upper, n, rhs);
}

bool solveDenseSpd(float* upper, int n, float* rhs) {
  return solveDenseSpdImpl(upper, n, rhs);
}

}  // namespace pnpba::bal_detail
