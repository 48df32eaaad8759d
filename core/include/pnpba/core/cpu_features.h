// What this CPU can run beyond the baseline x86-64 the library is built for. Hot kernels that
// gain from wider vectors are built a second time for AVX2 with FMA (bal/src/camera_row.h,
// optimize/src/landmark_elimination.h, ...) and chosen at run time by this, so that one binary
// runs on every x86-64 machine.
#pragma once

namespace pnpba {

// True where the CPU (and the OS) support AVX2 and FMA; evaluated once.
bool cpuHasAvx2Fma();

}  // namespace pnpba
