// The body of dense_cholesky.h's solves, included by dense_cholesky.cpp and
// dense_cholesky_avx2.cpp inside their own namespaces, after <Eigen/Cholesky> (at global scope:
// in the AVX2 build, under its renamed namespace). No include guard: each file includes it once.

template <typename Scalar>
bool solveDenseSpdImpl(Scalar* upper, int n, Scalar* rhs) {
  using Matrix = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>;
  using Vector = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;
  // One thread: Eigen parallelises only the factorisation's matrix products, which at these
  // sizes (441 to 1800 columns) gained nothing measurable and left the solver's other OpenMP
  // thread competing for the cache.
  Eigen::setNbThreads(1);
  Eigen::Map<Matrix> S(upper, n, n);
  Eigen::LLT<Eigen::Ref<Matrix>, Eigen::Upper> llt(S);  // in place
  if (llt.info() != Eigen::Success) return false;
  Eigen::Map<Vector> b(rhs, n);
  llt.solveInPlace(b);
  return true;
}
