// One block row of the reduced camera system S = U - W V^-1 W^T and its right-hand side, for
// camera a: the kernel of ReducedCameraSystem::buildReducedSystem (reduced_camera_system.h),
// where each thread builds whole rows. Built twice, like the dense Cholesky
// (dense_cholesky.h): for the baseline instruction set, and in camera_row_avx2.cpp for AVX2
// with FMA, used where the CPU has both; its 9 x 9 rank-2 updates are most of a solve's time.
// Raw arrays in, so that the two builds of Eigen never meet.
#pragma once

#include "pnpba/bal/bal_observation.h"

namespace pnpba::bal_detail {

// The solver's state the row reads, all column-major.
struct CameraRowData {
  const BalObservation* observations;
  const int *camera_start, *by_camera, *point_start, *by_point,
      *camera_by_point;       // ObservationIndex
  const double* Jc;           // 2 x 9 per observation: the scaled camera Jacobian
  const double* point_map;    // 3 x 3 per camera: a point Jacobian is Jc's columns 3-5 times it
  const double* point_scale;  // 3 per point: ... and then times this diagonal
  const double* V_inverse;    // 3 x 3 per point: the damped point block's inverse
  const double* g_p;          // 3 per point: the point gradient
  const double* g_c;          // 9 per camera: the camera gradient
  const double* U_damped;     // 9 x 9 per camera: the damped camera block
};

// Doubles per block of a row: 12 x 9, column-major, the 9 x 9 block in the top rows and three
// rows of padding (so that each column is three whole AVX2 vectors).
constexpr int kPaddedBlock = 108;

// Row a of S into `blocks` blocks at `rows` (kPaddedBlock doubles each, 32-byte aligned): block
// slot[b] for each camera b >= a that shares a point with a, block 0 for b = a; and
// -g_c + W V^-1 g_p of camera a into `rhs` (9 doubles). `slot` is indexed by camera; entries of
// other cameras are not read.
void buildCameraRow(const CameraRowData& data, int a, const int* slot, int blocks, double* rows,
                    double* rhs);

namespace avx2 {
// The same, built for AVX2 + FMA; call only where cpuHasAvx2Fma() (pnpba/core/cpu_features.h).
void buildCameraRow(const CameraRowData& data, int a, const int* slot, int blocks, double* rows,
                    double* rhs);
}  // namespace avx2

}  // namespace pnpba::bal_detail
