#include "reduced_camera_system.h"

#include <Eigen/Cholesky>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "camera_row.h"
#include "dense_cholesky.h"
#include "pnpba/core/cpu_features.h"
#include "pnpba/core/error.h"

namespace pnpba::bal_detail {

namespace {

// Note: products of fixed 9x2 by 2x9 blocks are written lazyProduct(): at that size Eigen would
// otherwise send them through its general matrix-matrix kernel (packing, blocking), which took
// more than half of the solver's time.

// Ceres's bounds on the LM diagonal (min_lm_diagonal, max_lm_diagonal).
constexpr double kMinDiagonal = 1e-6, kMaxDiagonal = 1e32;
// Conjugate gradients: relative residual to reach (Ceres's default eta for inexact steps).
constexpr double kCgTolerance = 1e-1;
constexpr int kCgMaxIterations = 500;

template <int N>
Eigen::Matrix<double, N, N> damped(const Eigen::Matrix<double, N, N>& block, double mu) {
  Eigen::Matrix<double, N, N> out = block;
  for (int i = 0; i < N; ++i) out(i, i) += std::clamp(block(i, i), kMinDiagonal, kMaxDiagonal) / mu;
  return out;
}

// The inverse of a symmetric 3 x 3 block by its adjugate, or false when the block is not
// positive definite (Sylvester's criterion: its leading minors a, a d - b^2 and det). A point's
// damped block is inverted at every solve, and Eigen's LLT and its solve against the identity
// took about 6 % of a dense solve's time where this takes a few dozen flops.
bool invertPositiveDefinite3(const Eigen::Matrix3d& m, Eigen::Matrix3d* inverse) {
  const double a = m(0, 0), b = m(0, 1), c = m(0, 2), d = m(1, 1), e = m(1, 2), f = m(2, 2);
  const double c00 = d * f - e * e, c01 = c * e - b * f, c02 = b * e - c * d;
  const double minor2 = a * d - b * b, det = a * c00 + b * c01 + c * c02;
  if (!(a > 0 && minor2 > 0 && det > 0)) return false;
  const double s = 1 / det;
  const double c11 = a * f - c * c, c12 = b * c - a * e;
  *inverse << c00 * s, c01 * s, c02 * s, c01 * s, c11 * s, c12 * s, c02 * s, c12 * s, minor2 * s;
  return true;
}

// rho(s) and sqrt(rho'(s)) of the loss at s = |r|^2 (width 1 px). Huber and Cauchy have
// rho'' <= 0, where Ceres's corrector reduces to scaling r and J by sqrt(rho').
void robust(RobustLoss loss, double s, double* rho, double* sqrt_rho1) {
  switch (loss) {
    case RobustLoss::kNone:
      *rho = s, *sqrt_rho1 = 1;
      return;
    case RobustLoss::kHuber:
      if (s <= 1) {
        *rho = s, *sqrt_rho1 = 1;
      } else {
        const double r = std::sqrt(s);
        *rho = 2 * r - 1, *sqrt_rho1 = std::sqrt(1 / r);
      }
      return;
    case RobustLoss::kCauchy:
      *rho = std::log1p(s), *sqrt_rho1 = std::sqrt(1 / (1 + s));
      return;
  }
}

}  // namespace

LinearSolverKind parseLinearSolverKind(const std::string& name) {
  if (name == "dense") return LinearSolverKind::kDense;
  if (name == "sparse") return LinearSolverKind::kSparse;
  if (name == "cg") return LinearSolverKind::kConjugateGradients;
  throw Error("unknown linear solver '" + name + "' (auto, dense, sparse, cg)");
}

RobustLoss parseRobustLoss(const std::string& name) {
  if (name == "none") return RobustLoss::kNone;
  if (name == "huber") return RobustLoss::kHuber;
  if (name == "cauchy") return RobustLoss::kCauchy;
  throw Error("robust: unknown loss '" + name + "' (none, huber, cauchy)");
}

ObservationIndex::ObservationIndex(const BalProblem& p) {
  const int n = static_cast<int>(p.observations.size());
  camera_start.assign(p.num_cameras + 1, 0);
  point_start.assign(p.num_points + 1, 0);
  for (const BalObservation& o : p.observations)
    ++camera_start[o.camera + 1], ++point_start[o.point + 1];
  for (int c = 0; c < p.num_cameras; ++c) camera_start[c + 1] += camera_start[c];
  for (int q = 0; q < p.num_points; ++q) point_start[q + 1] += point_start[q];
  by_camera.resize(n), by_point.resize(n);
  std::vector<int> next_c(camera_start.begin(), camera_start.end() - 1);
  std::vector<int> next_p(point_start.begin(), point_start.end() - 1);
  camera_by_point.resize(n);
  for (int i = 0; i < n; ++i) {
    by_camera[next_c[p.observations[i].camera]++] = i;
    const int m = next_p[p.observations[i].point]++;
    by_point[m] = i;
    camera_by_point[m] = p.observations[i].camera;
  }
  camera_partners = cameraPartners(p, *this);
}

std::vector<std::vector<int>> cameraPartners(const BalProblem& p, const ObservationIndex& index,
                                             size_t max_bits) {
  // One bit per camera pair, set point by point (each point's cameras are a run of
  // camera_by_point), then read row by row: the lists come out sorted, and no pair is listed once
  // per shared point to be sorted away (3000 cameras, 900k observations: 74 -> 7 ms). The bits
  // are at most max_bits: beyond that the rows are done in bands, a pass over the points each.
  const size_t nc = static_cast<size_t>(p.num_cameras);
  const size_t words = (nc + 63) / 64;
  const size_t band = std::max<size_t>(1, max_bits / (64 * words));
  std::vector<uint64_t> shares;
  std::vector<std::vector<int>> partners(nc);
  const std::vector<int>& cameras = index.camera_by_point;
  for (size_t first = 0; first < nc; first += band) {
    const size_t last = std::min(nc, first + band);
    shares.assign((last - first) * words, 0);
    for (int q = 0; q < p.num_points; ++q) {
      for (int x = index.point_start[q]; x < index.point_start[q + 1]; ++x) {
        const size_t a = cameras[x];
        if (a < first || a >= last) continue;
        for (int y = index.point_start[q]; y < index.point_start[q + 1]; ++y) {
          const size_t b = cameras[y];
          if (a < b) shares[(a - first) * words + b / 64] |= uint64_t{1} << (b % 64);
        }
      }
    }
    for (size_t a = first; a < last; ++a) {
      for (size_t w = 0; w < words; ++w) {
        for (uint64_t bits = shares[(a - first) * words + w]; bits != 0; bits &= bits - 1) {
          partners[a].push_back(static_cast<int>(64 * w + __builtin_ctzll(bits)));
        }
      }
    }
  }
  return partners;
}

double reducedSystemDensity(const BalProblem& p, const ObservationIndex& index) {
  double blocks = p.num_cameras;  // the diagonal
  for (const std::vector<int>& list : index.camera_partners) blocks += list.size();
  const double n = p.num_cameras;
  return blocks / (n * (n + 1) / 2);
}

// The block pattern of S (camera pairs that share a point, upper triangle) and, for the
// sparse solver, where each block's columns live in the compressed matrix.
//
// The sparse matrix is stored already in its fill-reducing order, computed by AMD on the
// cameras' block pattern (one entry per 9x9 block) as Ceres does, and factored without
// reordering. Left to Eigen, the ordering runs on the scalar matrix and copies it three times
// with its values: at 1000 cameras those copies were the solver's peak memory (38 MB, 127 bytes
// per observation), and the block order is as good (a block's 9 columns are indistinguishable).
struct ReducedCameraSystem::SparseStorage {
  std::vector<std::vector<int>> neighbours;  // per camera a: cameras b >= a sharing a point
  // Sparse only: camera a's block row and column in the ordered matrix.
  std::vector<int> position;
  // Sparse only: block (a, neighbours[a][k]) column c starts at base[a][k] + c * stride[a][k];
  // transposed[a][k]: the ordering put b before a, so the block is stored as its transpose.
  std::vector<std::vector<int>> base, stride;
  std::vector<std::vector<char>> transposed;
  using Ordering = Eigen::NaturalOrdering<int>;
  Eigen::SparseMatrix<double> matrix;  // upper blocks, column-major, in `position` order
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Upper, Ordering> ldlt;
  // Single precision: a float copy of the matrix (same pattern) and its factorisation.
  Eigen::SparseMatrix<float> matrix_float;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<float>, Eigen::Upper, Ordering> ldlt_float;
};

namespace {

// AMD on the cameras' block pattern: camera a's position in the fill-reducing order.
std::vector<int> blockOrdering(const std::vector<std::vector<int>>& neighbours) {
  const int nc = static_cast<int>(neighbours.size());
  std::vector<Eigen::Triplet<double>> entries;
  for (int a = 0; a < nc; ++a) {
    for (int b : neighbours[a]) entries.emplace_back(a, b, 1.0);
  }
  Eigen::SparseMatrix<double> pattern(nc, nc);
  pattern.setFromTriplets(entries.begin(), entries.end());
  // Eigen's orderings return the inverse permutation: new index -> old index.
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> new_to_old;
  Eigen::AMDOrdering<int>()(pattern, new_to_old);
  std::vector<int> position(nc);
  for (int k = 0; k < nc; ++k) position[new_to_old.indices()[k]] = k;
  return position;
}

}  // namespace

ReducedCameraSystem::ReducedCameraSystem(const BalProblem& problem, const ObservationIndex& index,
                                         LinearSolverKind kind, RobustLoss loss, int threads,
                                         bool single_precision)
    : single_precision_(single_precision),
      problem_(problem),
      index_(index),
      kind_(kind),
      loss_(loss),
      threads_(threads),
      nc_(problem.num_cameras),
      np_(problem.num_points),
      sparse_(std::make_unique<SparseStorage>()) {
  if (kind_ == LinearSolverKind::kConjugateGradients) {
    preconditioner_.resize(nc_);
  } else {
    buildPattern();
  }
  // The per-observation storage last: the sparse analysis's transient copies of the matrix
  // (buildPattern) then do not add to the solver's peak memory.
  const size_t n = problem.observations.size();
  Jc_.resize(n), point_map_.resize(nc_);
  U_.resize(nc_), U_damped_.resize(nc_), g_c_.resize(nc_);
  V_inverse_.resize(np_), g_p_.resize(np_);
}

void ReducedCameraSystem::buildPattern() {
  // The pattern, once: camera pairs through shared points.
  auto& nb = sparse_->neighbours;
  nb = index_.camera_partners;
  for (int a = 0; a < nc_; ++a) nb[a].insert(nb[a].begin(), a);  // the diagonal block first
  if (kind_ == LinearSolverKind::kDense) {
    dense_.setZero(9 * nc_, 9 * nc_);
    return;
  }
  // Column-major upper storage in the ordered positions: block column j holds the row blocks
  // i <= j that share a point, in increasing i, so each of its 9 columns has the same rows and
  // the block of i sits at rank(i in column j) * 9 in each.
  const std::vector<int>& position = sparse_->position = blockOrdering(nb);
  struct Placed {
    int row, a, k;  // ordered block row; the block (a, nb[a][k]) stored there
  };
  std::vector<std::vector<Placed>> rows_of_column(nc_);
  for (int a = 0; a < nc_; ++a) {
    for (size_t k = 0; k < nb[a].size(); ++k) {
      const int i = position[a], j = position[nb[a][k]];
      rows_of_column[std::max(i, j)].push_back({std::min(i, j), a, static_cast<int>(k)});
    }
  }
  for (auto& column : rows_of_column) {
    std::sort(column.begin(), column.end(),
              [](const Placed& x, const Placed& y) { return x.row < y.row; });
  }
  auto& m = sparse_->matrix;
  m.resize(9 * nc_, 9 * nc_);
  Eigen::VectorXi per_column(9 * nc_);
  for (int j = 0; j < nc_; ++j)
    per_column.segment<9>(9 * j).setConstant(9 * rows_of_column[j].size());
  m.reserve(per_column);
  for (int j = 0; j < nc_; ++j) {
    for (int c = 0; c < 9; ++c) {
      for (const Placed& p : rows_of_column[j]) {
        for (int r = 0; r < 9; ++r) m.insert(9 * p.row + r, 9 * j + c) = 0.0;
      }
    }
  }
  m.makeCompressed();
  sparse_->base.resize(nc_), sparse_->stride.resize(nc_), sparse_->transposed.resize(nc_);
  for (int a = 0; a < nc_; ++a) {
    sparse_->base[a].resize(nb[a].size());
    sparse_->stride[a].resize(nb[a].size());
    sparse_->transposed[a].resize(nb[a].size());
  }
  for (int j = 0; j < nc_; ++j) {
    const int count = static_cast<int>(rows_of_column[j].size());
    for (int rank = 0; rank < count; ++rank) {
      const Placed& p = rows_of_column[j][rank];
      sparse_->base[p.a][p.k] = m.outerIndexPtr()[9 * j] + 9 * rank;
      sparse_->stride[p.a][p.k] = 9 * count;
      sparse_->transposed[p.a][p.k] = position[p.a] > position[nb[p.a][p.k]];
    }
  }
  // The symbolic factorisation needs the pattern only.
  SparseStorage& sp = *sparse_;
  if (single_precision_) {
    sp.matrix_float = m.cast<float>();
    sp.ldlt_float.analyzePattern(sp.matrix_float);
  } else {
    sp.ldlt.analyzePattern(m);
  }
}

ReducedCameraSystem::~ReducedCameraSystem() = default;

double ReducedCameraSystem::cost(const double* cameras, const double* points) const {
  // Per-camera sums, then a serial sum: the same value for any thread count.
  std::vector<double> per_camera(nc_, 0.0);
#pragma omp parallel for schedule(dynamic, 8) num_threads(threads_)
  for (int a = 0; a < nc_; ++a) {
    const CameraRotation rotation = cameraRotation(cameras + 9 * a);
    double sum = 0;
    for (int i = index_.camera_start[a]; i < index_.camera_start[a + 1]; ++i) {
      const BalObservation& o = problem_.observations[index_.by_camera[i]];
      const Eigen::Vector2d r =
          snavelyResidual(cameras + 9 * a, rotation, points + 3 * o.point, o.u, o.v);
      double rho = 0, w = 0;
      robust(loss_, r.squaredNorm(), &rho, &w);
      sum += rho;
    }
    per_camera[a] = sum;
  }
  double total = 0;
  for (double v : per_camera) total += v;
  return 0.5 * total;
}

double ReducedCameraSystem::linearize(const double* cameras, const double* points) {
  const int n = static_cast<int>(problem_.observations.size());
  std::vector<CameraRotation> rotations(nc_);
  // The residuals are needed only here (the gradients carry them on); the points' diagonals
  // only at the first call, for the Jacobi scaling. Once the scales are fixed (every later call)
  // the Jacobians and gradients are scaled as they are formed, in the same pass.
  std::vector<Eigen::Vector2d> residual(n);
  const bool first = camera_scale_.empty();
  std::vector<Eigen::Vector3d> point_diagonal(first ? np_ : 0);
#pragma omp parallel num_threads(threads_)
  {
#pragma omp for schedule(static)
    for (int a = 0; a < nc_; ++a) {
      rotations[a] = cameraRotation(cameras + 9 * a);
      if (!first) {
        point_map_[a] = camera_scale_[a].segment<3>(3).cwiseInverse().asDiagonal() * rotations[a].R;
      }
    }
#pragma omp for schedule(static)
    for (int i = 0; i < n; ++i) {
      const BalObservation& o = problem_.observations[i];
      residual[i] = snavelyResidual(cameras + 9 * o.camera, rotations[o.camera],
                                    points + 3 * o.point, o.u, o.v, &Jc_[i]);
      double rho = 0, w = 1;
      robust(loss_, residual[i].squaredNorm(), &rho, &w);
      if (w != 1) residual[i] *= w, Jc_[i] *= w;
      if (!first) Jc_[i] = Jc_[i] * camera_scale_[o.camera].asDiagonal();
    }
#pragma omp for schedule(dynamic, 8)
    for (int a = 0; a < nc_; ++a) {
      U_[a].setZero(), g_c_[a].setZero();
      for (int k = index_.camera_start[a]; k < index_.camera_start[a + 1]; ++k) {
        const int i = index_.by_camera[k];
        U_[a].noalias() += Jc_[i].transpose().lazyProduct(Jc_[i]);
        g_c_[a].noalias() += Jc_[i].transpose() * residual[i];
      }
    }
#pragma omp for schedule(dynamic, 64)
    for (int q = 0; q < np_; ++q) {
      g_p_[q].setZero();
      Eigen::Vector3d diagonal = Eigen::Vector3d::Zero();
      for (int k = index_.point_start[q]; k < index_.point_start[q + 1]; ++k) {
        const int i = index_.by_point[k];
        const int a = problem_.observations[i].camera;
        const Matrix23 J = first ? Matrix23(Jc_[i].middleCols<3>(3) * rotations[a].R)
                                 : Matrix23(Jc_[i].middleCols<3>(3) * point_map_[a]);
        if (first) diagonal += J.colwise().squaredNorm().transpose();
        g_p_[q].noalias() += J.transpose() * residual[i];
      }
      if (first) point_diagonal[q] = diagonal;
      if (!first) g_p_[q] = g_p_[q].cwiseProduct(point_scale_[q]);
    }
  }
  // The gradient's max-norm in the problem's own variables, as Ceres reports and tests it.
  double max_norm = 0;
  for (int a = 0; a < nc_; ++a) {
    const Vector9 g = first ? g_c_[a] : Vector9(g_c_[a].cwiseQuotient(camera_scale_[a]));
    max_norm = std::max(max_norm, g.cwiseAbs().maxCoeff());
  }
  for (int q = 0; q < np_; ++q) {
    const Eigen::Vector3d g =
        first ? g_p_[q] : Eigen::Vector3d(g_p_[q].cwiseQuotient(point_scale_[q]));
    max_norm = std::max(max_norm, g.cwiseAbs().maxCoeff());
  }
  if (!first) return max_norm;

  camera_scale_.resize(nc_), point_scale_.resize(np_);
  for (int a = 0; a < nc_; ++a) {
    camera_scale_[a] = (1.0 + U_[a].diagonal().array().sqrt()).inverse().matrix();
  }
  for (int q = 0; q < np_; ++q) {
    point_scale_[q] = (1.0 + point_diagonal[q].array().sqrt()).inverse().matrix();
  }
#pragma omp parallel num_threads(threads_)
  {
#pragma omp for schedule(static)
    for (int i = 0; i < n; ++i) {
      Jc_[i] = Jc_[i] * camera_scale_[problem_.observations[i].camera].asDiagonal();
    }
#pragma omp for schedule(static)
    for (int a = 0; a < nc_; ++a) {
      point_map_[a] = camera_scale_[a].segment<3>(3).cwiseInverse().asDiagonal() * rotations[a].R;
    }
#pragma omp for schedule(static)
    for (int a = 0; a < nc_; ++a) {
      U_[a] = (camera_scale_[a] * camera_scale_[a].transpose()).cwiseProduct(U_[a]);
      g_c_[a] = g_c_[a].cwiseProduct(camera_scale_[a]);
    }
#pragma omp for schedule(static)
    for (int q = 0; q < np_; ++q) g_p_[q] = g_p_[q].cwiseProduct(point_scale_[q]);
  }
  return max_norm;
}

void ReducedCameraSystem::dampPoints(double mu) {
#pragma omp parallel for schedule(static) num_threads(threads_)
  for (int q = 0; q < np_; ++q) {
    // The point's block of the (scaled) J^T J, from its few observations: cheaper to form here
    // than to keep for every point.
    Eigen::Matrix3d V = Eigen::Matrix3d::Zero();
    for (int k = index_.point_start[q]; k < index_.point_start[q + 1]; ++k) {
      const int i = index_.by_point[k];
      const Matrix23 J = jp(i);
      V.noalias() += J.transpose() * J;
    }
    if (!invertPositiveDefinite3(damped<3>(V, mu), &V_inverse_[q])) {
      V_inverse_[q] = Eigen::Matrix3d::Constant(NAN);
    }
  }
#pragma omp parallel for schedule(static) num_threads(threads_)
  for (int a = 0; a < nc_; ++a) U_damped_[a] = damped<9>(U_[a], mu);
}

Matrix23 ReducedCameraSystem::jp(int i) const {
  const BalObservation& o = problem_.observations[i];
  return (Jc_[i].middleCols<3>(3) * point_map_[o.camera]) * point_scale_[o.point].asDiagonal();
}

Eigen::Matrix<double, 9, 3> ReducedCameraSystem::eliminationBlock(int i) const {
  return Jc_[i].transpose() * (jp(i) * V_inverse_[problem_.observations[i].point]);
}

Vector9 ReducedCameraSystem::cameraRhs(int a) const {
  Vector9 rhs = -g_c_[a];
  for (int k = index_.camera_start[a]; k < index_.camera_start[a + 1]; ++k) {
    const int i = index_.by_camera[k];
    rhs.noalias() += eliminationBlock(i) * g_p_[problem_.observations[i].point];
  }
  return rhs;
}

void ReducedCameraSystem::buildReducedSystem(Eigen::VectorXd* rhs) {
  rhs->resize(9 * nc_);
  // The in-place Cholesky of the last solve filled blocks outside the pattern.
  if (kind_ == LinearSolverKind::kDense) dense_.setZero();
  const auto& nb = sparse_->neighbours;
  // The kernel reads the solver's arrays as plain doubles (camera_row.h).
  static_assert(sizeof(Matrix29) == 18 * sizeof(double) && sizeof(Matrix9) == 81 * sizeof(double) &&
                sizeof(Vector9) == 9 * sizeof(double) &&
                sizeof(Eigen::Matrix3d) == 9 * sizeof(double) &&
                sizeof(Eigen::Vector3d) == 3 * sizeof(double));
  const CameraRowData data{
      problem_.observations.data(), index_.camera_start.data(), index_.by_camera.data(),
      index_.point_start.data(),    index_.by_point.data(),     index_.camera_by_point.data(),
      Jc_.data()->data(),           point_map_.data()->data(),  point_scale_.data()->data(),
      V_inverse_.data()->data(),    g_p_.data()->data(),        g_c_.data()->data(),
      U_damped_.data()->data()};
  const auto build = cpuHasAvx2Fma() ? avx2::buildCameraRow : bal_detail::buildCameraRow;
#pragma omp parallel num_threads(threads_)
  {
    std::vector<int> slot(nc_, -1);
    std::vector<double> storage;
#pragma omp for schedule(dynamic, 4)
    for (int a = 0; a < nc_; ++a) {
      const int blocks = static_cast<int>(nb[a].size());  // nb[a][0] == a
      storage.resize(kPaddedBlock * static_cast<size_t>(blocks) + 4);
      double* rows = storage.data();  // the kernel's blocks are 32-byte aligned
      while (reinterpret_cast<std::uintptr_t>(rows) % 32 != 0) ++rows;
      for (int k = 0; k < blocks; ++k) slot[nb[a][k]] = k;
      build(data, a, slot.data(), blocks, rows, rhs->data() + 9 * a);
      for (int k = 0; k < blocks; ++k) {
        const int b = nb[a][k];
        const Eigen::Map<const Matrix9, 0, Eigen::OuterStride<12>> block(rows + kPaddedBlock * k);
        if (kind_ == LinearSolverKind::kDense) {
          dense_.block<9, 9>(9 * a, 9 * b) = block;
        } else {
          double* values = sparse_->matrix.valuePtr();
          const bool transposed = sparse_->transposed[a][k];
          for (int c = 0; c < 9; ++c) {
            Eigen::Map<Vector9> column(values + sparse_->base[a][k] + c * sparse_->stride[a][k]);
            if (transposed) {
              column = block.row(c).transpose();
            } else {
              column = block.col(c);
            }
          }
        }
        slot[b] = -1;
      }
    }
  }
}

bool ReducedCameraSystem::solveDense(const Eigen::VectorXd& rhs, Eigen::VectorXd* dc) {
  const int n = static_cast<int>(dense_.rows());
  const bool avx2 = cpuHasAvx2Fma();
  if (single_precision_) {
    dense_float_ = dense_.cast<float>();
    Eigen::VectorXf x = rhs.cast<float>();
    const bool ok = avx2 ? avx2::solveDenseSpd(dense_float_.data(), n, x.data(), threads_)
                         : solveDenseSpd(dense_float_.data(), n, x.data(), threads_);
    *dc = x.cast<double>();
    return ok;
  }
  *dc = rhs;
  return avx2 ? avx2::solveDenseSpd(dense_.data(), n, dc->data(), threads_)
              : solveDenseSpd(dense_.data(), n, dc->data(), threads_);
}

bool ReducedCameraSystem::solveSparse(const Eigen::VectorXd& rhs_by_camera, Eigen::VectorXd* dc) {
  SparseStorage& sp = *sparse_;
  // The matrix is in the ordered positions; so are its right-hand side and solution.
  Eigen::VectorXd rhs(9 * nc_);
  for (int a = 0; a < nc_; ++a)
    rhs.segment<9>(9 * sp.position[a]) = rhs_by_camera.segment<9>(9 * a);
  auto byCamera = [&](const Eigen::VectorXd& ordered) {
    dc->resize(9 * nc_);
    for (int a = 0; a < nc_; ++a) dc->segment<9>(9 * a) = ordered.segment<9>(9 * sp.position[a]);
  };
  if (single_precision_) {
    // Same pattern: copy the values only.
    Eigen::Map<Eigen::VectorXf>(sp.matrix_float.valuePtr(), sp.matrix_float.nonZeros()) =
        Eigen::Map<const Eigen::VectorXd>(sp.matrix.valuePtr(), sp.matrix.nonZeros()).cast<float>();
    sp.ldlt_float.factorize(sp.matrix_float);
    if (sp.ldlt_float.info() != Eigen::Success) return false;
    if ((sp.ldlt_float.vectorD().array() <= 0).any()) return false;
    byCamera(sp.ldlt_float.solve(rhs.cast<float>()).cast<double>());
    return true;
  }
  sp.ldlt.factorize(sp.matrix);
  if (sp.ldlt.info() != Eigen::Success) return false;
  if ((sp.ldlt.vectorD().array() <= 0).any()) return false;
  byCamera(sp.ldlt.solve(rhs));
  return true;
}

void ReducedCameraSystem::multiplySchur(const Eigen::VectorXd& x, Eigen::VectorXd* y) const {
  std::vector<Eigen::Vector3d> w(np_);
  y->resize(9 * nc_);
#pragma omp parallel num_threads(threads_)
  {
#pragma omp for schedule(dynamic, 64)
    for (int q = 0; q < np_; ++q) {
      Eigen::Vector3d z = Eigen::Vector3d::Zero();
      for (int k = index_.point_start[q]; k < index_.point_start[q + 1]; ++k) {
        const int i = index_.by_point[k];
        z.noalias() +=
            jp(i).transpose() * (Jc_[i] * x.segment<9>(9 * problem_.observations[i].camera));
      }
      w[q] = V_inverse_[q] * z;
    }
#pragma omp for schedule(dynamic, 8)
    for (int a = 0; a < nc_; ++a) {
      Vector9 ya = U_damped_[a] * x.segment<9>(9 * a);
      for (int k = index_.camera_start[a]; k < index_.camera_start[a + 1]; ++k) {
        const int i = index_.by_camera[k];
        ya.noalias() -= Jc_[i].transpose() * (jp(i) * w[problem_.observations[i].point]);
      }
      y->segment<9>(9 * a) = ya;
    }
  }
}

bool ReducedCameraSystem::solveConjugateGradients(const Eigen::VectorXd& rhs, Eigen::VectorXd* dc) {
  // Block-Jacobi preconditioner: the inverted diagonal blocks of S.
  bool ok = true;
#pragma omp parallel for schedule(dynamic, 8) num_threads(threads_) reduction(&& : ok)
  for (int a = 0; a < nc_; ++a) {
    Matrix9 S_aa = U_damped_[a];
    for (int k = index_.camera_start[a]; k < index_.camera_start[a + 1]; ++k) {
      const int i = index_.by_camera[k];
      const Eigen::Matrix<double, 9, 3> W = Jc_[i].transpose() * jp(i);
      const Eigen::Matrix<double, 9, 3> WV = W * V_inverse_[problem_.observations[i].point];
      S_aa.noalias() -= WV.lazyProduct(W.transpose());
    }
    const Eigen::LLT<Matrix9> llt(S_aa);
    ok = ok && llt.info() == Eigen::Success;
    preconditioner_[a] = llt.solve(Matrix9::Identity());
  }
  if (!ok) return false;
  auto precondition = [this](const Eigen::VectorXd& r, Eigen::VectorXd* z) {
    z->resize(r.size());
    for (int a = 0; a < nc_; ++a) z->segment<9>(9 * a) = preconditioner_[a] * r.segment<9>(9 * a);
  };
  Eigen::VectorXd x = Eigen::VectorXd::Zero(rhs.size()), r = rhs, z, p, Sp;
  precondition(r, &z);
  p = z;
  double rz = r.dot(z);
  const double target = kCgTolerance * rhs.norm();
  cg_iterations_ = 0;
  for (int it = 0; it < kCgMaxIterations && r.norm() > target; ++it) {
    multiplySchur(p, &Sp);
    const double pSp = p.dot(Sp);
    if (!(pSp > 0)) return false;
    const double alpha = rz / pSp;
    x += alpha * p;
    r -= alpha * Sp;
    precondition(r, &z);
    const double rz_next = r.dot(z);
    p = z + (rz_next / rz) * p;
    rz = rz_next;
    ++cg_iterations_;
  }
  *dc = x;
  return x.allFinite();
}

double ReducedCameraSystem::backSubstitute(const Eigen::VectorXd& dc, Eigen::VectorXd* dp) const {
  dp->resize(3 * np_);
  // The model's predicted decrease -g.d - 1/2 |J d|^2 (g = J^T r the gradient) comes with the
  // points: each observation's J d = Jc dc + jp dp needs the point's step, and its camera part
  // is what the elimination has just formed. Summed per fixed chunk of points, then in chunk
  // order, so the sum does not depend on the threads' timing.
  constexpr int kChunk = 64;
  std::vector<double> chunk_change((np_ + kChunk - 1) / kChunk, 0.0);
#pragma omp parallel num_threads(threads_)
  {
    std::vector<Eigen::Vector2d> camera_part;
    std::vector<Matrix23> point_jacobian;
#pragma omp for schedule(dynamic, 1)
    for (int chunk = 0; chunk < static_cast<int>(chunk_change.size()); ++chunk) {
      double change = 0;
      for (int q = chunk * kChunk; q < std::min(np_, (chunk + 1) * kChunk); ++q) {
        const int begin = index_.point_start[q], end = index_.point_start[q + 1];
        camera_part.resize(end - begin), point_jacobian.resize(end - begin);
        Eigen::Vector3d rhs = -g_p_[q];
        for (int k = begin; k < end; ++k) {
          const int i = index_.by_point[k];
          camera_part[k - begin] = Jc_[i] * dc.segment<9>(9 * problem_.observations[i].camera);
          point_jacobian[k - begin] = jp(i);
          rhs.noalias() -= point_jacobian[k - begin].transpose() * camera_part[k - begin];
        }
        const Eigen::Vector3d step = V_inverse_[q] * rhs;
        dp->segment<3>(3 * q) = step;
        change -= g_p_[q].dot(step);
        for (int k = 0; k < end - begin; ++k) {
          change -= 0.5 * (camera_part[k] + point_jacobian[k] * step).squaredNorm();
        }
      }
      chunk_change[chunk] = change;
    }
  }
  double total = 0;
  for (int a = 0; a < nc_; ++a) total -= g_c_[a].dot(dc.segment<9>(9 * a));
  for (double c : chunk_change) total += c;
  return total;
}

bool ReducedCameraSystem::solve(double mu, Eigen::VectorXd* dc, Eigen::VectorXd* dp) {
  dampPoints(mu);
  for (const Eigen::Matrix3d& m : V_inverse_) {
    if (!m.allFinite()) return false;
  }
  Eigen::VectorXd rhs;
  bool ok = false;
  if (kind_ == LinearSolverKind::kConjugateGradients) {
    rhs.resize(9 * nc_);
#pragma omp parallel for schedule(dynamic, 8) num_threads(threads_)
    for (int a = 0; a < nc_; ++a) rhs.segment<9>(9 * a) = cameraRhs(a);
    ok = solveConjugateGradients(rhs, dc);
  } else {
    buildReducedSystem(&rhs);
    ok = kind_ == LinearSolverKind::kDense ? solveDense(rhs, dc) : solveSparse(rhs, dc);
  }
  if (!ok || !dc->allFinite()) return false;
  model_cost_change_ = backSubstitute(*dc, dp);
  if (!dp->allFinite()) return false;
  // Back to the problem's own variables.
  for (int a = 0; a < nc_; ++a)
    dc->segment<9>(9 * a) = dc->segment<9>(9 * a).cwiseProduct(camera_scale_[a]);
  for (int q = 0; q < np_; ++q)
    dp->segment<3>(3 * q) = dp->segment<3>(3 * q).cwiseProduct(point_scale_[q]);
  return true;
}

}  // namespace pnpba::bal_detail
