// The definitions of dense_cholesky.h's solves, included by dense_cholesky.cpp (in
// pnpba::bal_detail) and dense_cholesky_avx2.cpp (in pnpba::bal_detail::avx2) after
// <Eigen/Cholesky> and <algorithm> (at global scope: in the AVX2 build, under its renamed
// namespace). No include guard: each file includes it once.

namespace {

// Columns per block: a diagonal block is factored by one thread while the others wait, so
// blocks stay small; the panels and trailing updates between them are shared out. 48-64 were
// the fastest on two threads at 441 and 900 columns (0.78 and 5.4 ms a factorisation and
// solve, where Eigen's LLT took 1.5 and 7.8-8.2 ms).
constexpr int kCholeskyBlock = 64;

// Right-looking blocked Cholesky S = U^T U of the upper triangle, in place. Each step factors
// one diagonal block, solves its row panel (U_kk^-T S_kj) and subtracts the panel's products
// from the trailing upper triangle, the last two shared out by column blocks between the
// threads of the enclosing team (orphaned worksharing: without a team it runs serially). Every
// block's arithmetic is the same whichever thread does it. Sets *ok (shared) to false when a
// diagonal block is not positive definite.
template <typename Scalar>
void factorUpperSteps(Scalar* upper, int n, bool* ok) {
  using Matrix = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>;
  Eigen::Map<Matrix> S(upper, n, n);
  const int steps = (n + kCholeskyBlock - 1) / kCholeskyBlock;
  for (int k = 0; k < steps; ++k) {
    const int k0 = k * kCholeskyBlock, kb = std::min(kCholeskyBlock, n - k0);
#pragma omp single
    {
      Eigen::Ref<Matrix> diagonal = S.block(k0, k0, kb, kb);
      Eigen::LLT<Eigen::Ref<Matrix>, Eigen::Upper> llt(diagonal);  // in place
      *ok = llt.info() == Eigen::Success;
    }  // the barrier: every thread reads *ok and the factored block after it
    if (!*ok) return;
    const auto U_kk = S.block(k0, k0, kb, kb).template triangularView<Eigen::Upper>();
#pragma omp for schedule(dynamic, 1)
    for (int j = k + 1; j < steps; ++j) {
      const int j0 = j * kCholeskyBlock, jb = std::min(kCholeskyBlock, n - j0);
      U_kk.transpose().solveInPlace(S.block(k0, j0, kb, jb));
    }
    // Column block j takes rows k0 + kb to its own end (its upper part and diagonal block).
    // Largest first, so that the threads finish together.
#pragma omp for schedule(dynamic, 1)
    for (int j = steps - 1; j > k; --j) {
      const int j0 = j * kCholeskyBlock, jb = std::min(kCholeskyBlock, n - j0);
      const int r0 = k0 + kb, rows = j0 + jb - r0;
      S.block(r0, j0, rows, jb).noalias() -=
          S.block(k0, r0, kb, rows).transpose() * S.block(k0, j0, kb, jb);
    }
  }
}

// One thread runs the steps outside any team: a team of one would leave Eigen's products free
// to open a nested team of their own for every block (measured: 15x slower at 441 columns).
// In a team of two or more Eigen keeps its products serial.
template <typename Scalar>
bool factorUpper(Scalar* upper, int n, int threads) {
  bool ok = true;
  if (threads > 1) {
#pragma omp parallel num_threads(threads)
    factorUpperSteps(upper, n, &ok);
  } else {
    factorUpperSteps(upper, n, &ok);
  }
  return ok;
}

template <typename Scalar>
bool solveDenseSpdImpl(Scalar* upper, int n, Scalar* rhs, int threads) {
  using Matrix = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>;
  using Vector = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;
  if (!factorUpper(upper, n, threads)) return false;
  const Eigen::Map<const Matrix> U(upper, n, n);
  Eigen::Map<Vector> b(rhs, n);
  U.template triangularView<Eigen::Upper>().transpose().solveInPlace(b);
  U.template triangularView<Eigen::Upper>().solveInPlace(b);
  return true;
}

}  // namespace

bool solveDenseSpd(double* upper, int n, double* rhs, int threads) {
  return solveDenseSpdImpl(upper, n, rhs, threads);
}

bool solveDenseSpd(float* upper, int n, float* rhs, int threads) {
  return solveDenseSpdImpl(upper, n, rhs, threads);
}
