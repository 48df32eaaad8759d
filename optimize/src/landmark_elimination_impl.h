// The definitions of landmark_elimination.h's kernels, included by landmark_elimination.cpp
// (in namespace pnpba) and landmark_elimination_avx2.cpp (in pnpba::avx2) after <Eigen/Core> and
// <Eigen/Geometry> (at global scope: in the AVX2 build, under its renamed namespace). No include
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
    // D = adj(A) / det(A). The products use adj(A) and are scaled by 1/det at the end, so that
    // the division's latency overlaps them instead of stalling every one.
    Eigen::Matrix3d adj;
    adj.row(0) = A.col(1).cross(A.col(2)).transpose();
    adj.row(1) = A.col(2).cross(A.col(0)).transpose();
    adj.row(2) = A.col(0).cross(A.col(1)).transpose();
    const double inv_det = 1.0 / adj.row(0).dot(A.col(0));
    const Eigen::Map<const Eigen::Vector3d> b(bl + l.bl);
    for (size_t i = l.adj_begin; i < l.adj_end; ++i) {
      const int oi = pose_offset[adjacency[i].pose];
      const Matrix63 HiAdj = Eigen::Map<const Matrix63>(hpl + adjacency[i].hpl) * adj;
      Eigen::Map<Vector6> rhs_i(rhs + oi);
      const Vector6 r = HiAdj * b;
      rhs_i -= inv_det * r;
      for (size_t j = l.adj_begin; j < l.adj_end; ++j) {
        const int oj = pose_offset[adjacency[j].pose];
        if (oj > oi) continue;
        SBlock Sij(S + oi + static_cast<size_t>(oj) * lda, Eigen::OuterStride<>(lda));
        const Eigen::Matrix<double, 6, 6> P =
            HiAdj * Eigen::Map<const Matrix63>(hpl + adjacency[j].hpl).transpose();
        Sij -= inv_det * P;
      }
    }
    Eigen::Map<Eigen::Matrix3d>(dinv + l.hll) = inv_det * adj;
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
