// The definition of camera_row.h's kernel, included by camera_row.cpp (in pnpba::bal_detail) and
// camera_row_avx2.cpp (in pnpba::bal_detail::avx2) after <Eigen/Core> (at global scope: in the
// AVX2 build, under its renamed namespace). No include guard: each file includes it once.

void buildCameraRow(const CameraRowData& d, int a, const int* slot, int blocks, double* rows,
                    double* rhs) {
  using Matrix9 = Eigen::Matrix<double, 9, 9>;
  using Vector9 = Eigen::Matrix<double, 9, 1>;
  using Matrix29 = Eigen::Matrix<double, 2, 9>;
  using Matrix23 = Eigen::Matrix<double, 2, 3>;
  // The point Jacobian of observation i: the translation columns of its camera Jacobian, mapped
  // by its camera and scaled by its point (the solver stores no point Jacobians).
  auto jp = [&d](int i) -> Matrix23 {
    const BalObservation& o = d.observations[i];
    const Eigen::Map<const Matrix29> Jc(d.Jc + 18 * static_cast<size_t>(i));
    return (Jc.middleCols<3>(3) * Eigen::Map<const Eigen::Matrix3d>(d.point_map + 9 * o.camera)) *
           Eigen::Map<const Eigen::Vector3d>(d.point_scale + 3 * static_cast<size_t>(o.point))
               .asDiagonal();
  };
  // 12 x 9 blocks, three rows of padding below each 9 x 9 one: a column is then three whole
  // 4-double vectors, where 9 rows leave a scalar tail on every column of every rank-2 update
  // (the updates are most of the kernel's time).
  using Matrix12x9 = Eigen::Matrix<double, 12, 9>;
  using Matrix12x3 = Eigen::Matrix<double, 12, 3>;
  using Matrix12x2 = Eigen::Matrix<double, 12, 2>;
  auto block = [rows](int k) {
    return Eigen::Map<Matrix12x9, Eigen::Aligned32>(rows + kPaddedBlock * static_cast<size_t>(k));
  };
  for (int k = 0; k < blocks; ++k) block(k).setZero();
  block(0).topRows<9>() = Eigen::Map<const Matrix9>(d.U_damped + 81 * a);
  Vector9 rhs_a = -Eigen::Map<const Vector9>(d.g_c + 9 * a);
  Matrix12x3 T = Matrix12x3::Zero();
  for (int k = d.camera_start[a]; k < d.camera_start[a + 1]; ++k) {
    const int i = d.by_camera[k];
    const int q = d.observations[i].point;
    const Eigen::Map<const Matrix29> Jc_i(d.Jc + 18 * static_cast<size_t>(i));
    // W_i V^-1: camera i's share of the point's elimination.
    T.topRows<9>().noalias() =
        Jc_i.transpose() *
        (jp(i) * Eigen::Map<const Eigen::Matrix3d>(d.V_inverse + 9 * static_cast<size_t>(q)));
    rhs_a.noalias() +=
        T.topRows<9>() * Eigen::Map<const Eigen::Vector3d>(d.g_p + 3 * static_cast<size_t>(q));
    for (int m = d.point_start[q]; m < d.point_start[q + 1]; ++m) {
      const int b = d.camera_by_point[m];
      if (b < a) continue;
      const int i2 = d.by_point[m];
      const Matrix12x2 TJ = T.lazyProduct(jp(i2).transpose());
      block(slot[b]).noalias() -=
          TJ.lazyProduct(Eigen::Map<const Matrix29>(d.Jc + 18 * static_cast<size_t>(i2)));
    }
  }
  Eigen::Map<Vector9> out(rhs);
  out = rhs_a;
}
