// Private to the depth-only registration (registration.cpp): the FPFH's angle bin floor(11
// (atan2(y, x) + pi) / (2 pi)), clamped to 0..10, without calling atan2 in the common case. atan2
// was a third of the pair features' time (fpfh.cpp, 220 000 pairs a cloud in a rendered room). A
// polynomial within 4.1e-8 rad of atan on [0, 1] places the angle; only where that leaves the bin
// in doubt (within 1e-6 of a bin edge, or both arguments zero, whose signs atan2 reads) is atan2
// itself asked. The bin is therefore the one atan2 gives, to the last case
// (tests/pipeline/angle_bin_test.cpp).
#pragma once

#include <cmath>

namespace pnpba {

// The bin as atan2 places it: the definition, and the slow path of fastAngleBin.
inline int exactAngleBin(double y, double x) {
  const int b = static_cast<int>(std::floor(11 * (std::atan2(y, x) + M_PI) / (2.0 * M_PI)));
  return b >= 11 ? 10 : (b < 0 ? 0 : b);
}

inline int fastAngleBin(double y, double x) {
  const double ax = std::abs(x), ay = std::abs(y);
  const double big = ax > ay ? ax : ay, small = ax > ay ? ay : ax;
  if (big == 0) return exactAngleBin(y, x);
  const double z = small / big, z2 = z * z;
  // Least-squares fit of atan(z) / z in z^2 on [0, 1] (degree 7; largest error 4.1e-8 rad).
  double a = -0.0040732905484800602;
  a = a * z2 + 0.021946545624836764;
  a = a * z2 - 0.056063087000463752;
  a = a * z2 + 0.096562502668578049;
  a = a * z2 - 0.13915799995588585;
  a = a * z2 + 0.19948508569705256;
  a = a * z2 - 0.33330106645107571;
  a = a * z2 + 0.99999943683630388;
  a *= z;
  if (ay > ax) a = M_PI / 2 - a;
  if (x < 0) a = M_PI - a;
  if (y < 0) a = -a;
  const double t = 11 * (a + M_PI) / (2.0 * M_PI);
  const double below = std::floor(t);
  // 1e-6 of a bin is 5.7e-7 rad, fourteen times the fit's error.
  if (t - below < 1e-6 || below + 1 - t < 1e-6) return exactAngleBin(y, x);
  const int b = static_cast<int>(below);
  return b >= 11 ? 10 : (b < 0 ? 0 : b);
}

}  // namespace pnpba
