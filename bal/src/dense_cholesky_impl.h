// The definitions of dense_cholesky.h's solves, included by dense_cholesky.cpp (in
// pnpba::bal_detail) and dense_cholesky_avx2.cpp (in pnpba::bal_detail::avx2) after
// <Eigen/Cholesky> (at global scope: in the AVX2 build, under its renamed namespace). No include
// guard: each file includes it once.

namespace {

template <typename Scalar>
bool solveDenseSpdImpl(Scalar* upper, int n, Scalar* rhs) {
  using Matrix = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>;
  using Vector = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;
  // Eigen's threads left as they are (a process-wide setting): its blocked factorisation
  // parallelises only the matrix products, which at these sizes (441 to 1800 columns) ran the
  // same on one thread as on two.
  Eigen::Map<Matrix> S(upper, n, n);
  Eigen::LLT<Eigen::Ref<Matrix>, Eigen::Upper> llt(S);  // in place
  if (llt.info() != Eigen::Success) return false;
  Eigen::Map<Vector> b(rhs, n);
  llt.solveInPlace(b);
  return true;
}

}  // namespace

bool solveDenseSpd(double* upper, int n, double* rhs) { return solveDenseSpdImpl(upper, n, rhs); }

bool solveDenseSpd(float* upper, int n, float* rhs) { return solveDenseSpdImpl(upper, n, rhs); }
