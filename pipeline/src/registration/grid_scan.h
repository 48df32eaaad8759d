// Private to the depth-only registration (registration.cpp): the inner scan of the grid neighbour
// search (grid_neighbours.cpp), eight candidates at a time where the CPU has AVX-512
// (grid_scan_avx512.cpp, built with -mavx512f -mavx512vl and nothing contracted), four where it has
// AVX2 (grid_scan_avx2.cpp, -mavx2, nothing contracted): each squared distance is the scalar
// code's, ((dx dx + dy dy) + dz dz) with its three products rounded, and the candidates kept are
// written in the order the scalar scan writes them, so the neighbours are the same to the bit.
#pragma once

#include <cstddef>

namespace pnpba {

// Candidates t in [from, to) of the coordinate arrays whose squared distance from (x, y, z) is
// below r2, appended at `kept` to distance2 and id (ids[t] for each): returns the new count.
// Call only where the CPU has AVX-512F and AVX-512VL.
size_t scanRunAvx512(const double* xs, const double* ys, const double* zs, const int* ids, int from,
                     int to, double x, double y, double z, double r2, double* distance2, int* id,
                     size_t kept);

// The same, four at a time. It writes four entries at every step, the kept ones first, so
// distance2 and id need room for three entries past the last candidate the run can keep.
// Call only where the CPU has AVX2.
size_t scanRunAvx2(const double* xs, const double* ys, const double* zs, const int* ids, int from,
                   int to, double x, double y, double z, double r2, double* distance2, int* id,
                   size_t kept);

}  // namespace pnpba
