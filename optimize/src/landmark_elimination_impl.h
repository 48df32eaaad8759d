// The definitions of landmark_elimination.h's kernels, included by landmark_elimination.cpp
// (in namespace pnpba) and landmark_elimination_avx2.cpp (in pnpba::avx2) after <Eigen/Core> and
// <Eigen/LU> (at global scope: in the AVX2 build, under its renamed namespace). No include
// guard: each file includes it once.

void eliminateLandmarks63(const LandmarkBlocks* landmarks, size_t count,
                          const AdjacentBlock* adjacency, const int* pose_offset, const double* hll,
                          const double* bl, const double* hpl, double lambda, double* dinv,
                          double* S, int lda, double* rhs) {
  using Matrix63 = Eigen::Matrix<double, 6, 3>;
  using Vector6 = Eigen::Matrix<double, 6, 1>;
  using SBlock = Eigen::Map<Eigen::Matrix<double, 6, 6>, 0, Eigen::OuterStride<>>;
  for (size_t k = 0; k < count; ++k) {
    const LandmarkBlocks& l = landmarks[k];
    Eigen::Matrix3d A = Eigen::Map<const Eigen::Matrix3d>(hll + l.hll);
    A.diagonal().array() += lambda;
    Eigen::Map<Eigen::Matrix3d> D(dinv + l.hll);
    D = A.inverse();
    const Eigen::Map<const Eigen::Vector3d> b(bl + l.bl);
    for (size_t i = l.adj_begin; i < l.adj_end; ++i) {
      const int oi = pose_offset[adjacency[i].pose];
      const Matrix63 HiD = Eigen::Map<const Matrix63>(hpl + adjacency[i].hpl) * D;
      Eigen::Map<Vector6> rhs_i(rhs + oi);
      rhs_i.noalias() -= HiD * b;
      for (size_t j = l.adj_begin; j < l.adj_end; ++j) {
        const int oj = pose_offset[adjacency[j].pose];
        if (oj > oi) continue;
        SBlock Sij(S + oi + static_cast<size_t>(oj) * lda, Eigen::OuterStride<>(lda));
        Sij.noalias() -= HiD * Eigen::Map<const Matrix63>(hpl + adjacency[j].hpl).transpose();
      }
    }
  }
}

void backSubstitute63(const LandmarkBlocks* landmarks, size_t count, const AdjacentBlock* adjacency,
                      const int* pose_offset, const double* hpl, const double* dinv,
                      const double* bl, const double* xp, double* xl) {
  using Matrix63 = Eigen::Matrix<double, 6, 3>;
  using Vector6 = Eigen::Matrix<double, 6, 1>;
  for (size_t k = 0; k < count; ++k) {
    const LandmarkBlocks& l = landmarks[k];
    Eigen::Vector3d r = Eigen::Map<const Eigen::Vector3d>(bl + l.bl);
    for (size_t i = l.adj_begin; i < l.adj_end; ++i) {
      r.noalias() -= Eigen::Map<const Matrix63>(hpl + adjacency[i].hpl).transpose() *
                     Eigen::Map<const Vector6>(xp + pose_offset[adjacency[i].pose]);
    }
    Eigen::Map<Eigen::Vector3d> x(xl + l.bl);
    x = Eigen::Map<const Eigen::Matrix3d>(dinv + l.hll) * r;
  }
}
