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

bool cpuHasAvx2Fma() {
  static const bool has = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  return has;
}

}  // namespace pnpba::bal_detail
