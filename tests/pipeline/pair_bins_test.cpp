// The four-wide pair features (pipeline/src/registration/pair_bins.h) must give the scalar
// function's bins in every case they settle, and leave it the rest: otherwise the descriptors, and
// the registration, would change with the CPU.
#include "pair_bins.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "pnpba/core/cpu_features.h"

namespace pnpba {
namespace {

struct OrientedPoint {
  Eigen::Vector3d p, n;
};

// Compares every lane of pairBinsAvx2 with pairBins over the given pairs (first point fixed per
// group of four); returns how many lanes the kernel settled itself.
int expectSameBins(const std::vector<std::pair<OrientedPoint, OrientedPoint>>& pairs) {
  int settled = 0;
  for (size_t g = 0; g + 4 <= pairs.size(); g += 4) {
    const OrientedPoint& a = pairs[g].first;
    const double* p2[4];
    const double* n2[4];
    for (int l = 0; l < 4; ++l) {
      p2[l] = pairs[g + l].second.p.data();
      n2[l] = pairs[g + l].second.n.data();
    }
    PairBins out[4];
    const int left = pairBinsAvx2(a.p.data(), a.n.data(), p2, n2, out);
    for (int l = 0; l < 4; ++l) {
      if (left & (1 << l)) continue;
      ++settled;
      const OrientedPoint& b = pairs[g + l].second;
      const PairBins s = pairBins(a.p, a.n, b.p, b.n);
      EXPECT_EQ(out[l].theta, s.theta) << "pair " << g + l;
      EXPECT_EQ(out[l].alpha, s.alpha) << "pair " << g + l;
      EXPECT_EQ(out[l].phi, s.phi) << "pair " << g + l;
      EXPECT_EQ(out[l].reversible, s.reversible) << "pair " << g + l;
    }
  }
  return settled;
}

TEST(PairBins, FourWideEqualsScalarOnRandomPairs) {
  if (!cpuHasAvx2Fma()) GTEST_SKIP() << "no AVX2 on this CPU";
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> coord(-2.0, 2.0), offset(-0.1, 0.1);
  auto unit = [&] { return Eigen::Vector3d(coord(rng), coord(rng), coord(rng)).normalized(); };
  std::vector<std::pair<OrientedPoint, OrientedPoint>> pairs;
  for (int g = 0; g < 250000; ++g) {
    const OrientedPoint a{{coord(rng), coord(rng), coord(rng)}, unit()};
    for (int l = 0; l < 4; ++l) {
      pairs.push_back({a, {a.p + Eigen::Vector3d(offset(rng), offset(rng), offset(rng)), unit()}});
    }
  }
  EXPECT_GT(expectSameBins(pairs), 990000);
}

TEST(PairBins, FourWideLeavesSpecialCasesOrMatchesThem) {
  if (!cpuHasAvx2Fma()) GTEST_SKIP() << "no AVX2 on this CPU";
  // Coincident points, normals along the line (zero cross product), equal normals (angles of
  // 0 and at bin edges), opposite normals, signed zeros, a point on a plane of its neighbours.
  const Eigen::Vector3d o(0.5, -0.25, 2.0), z(0, 0, 1), x(1, 0, 0);
  std::vector<std::pair<OrientedPoint, OrientedPoint>> pairs;
  const std::vector<OrientedPoint> partners = {
      {o, z},
      {o + 0.01 * z, z},
      {o + 0.01 * x, z},
      {o + 0.01 * x, -z},
      {o - 0.01 * x, x},
      {o + Eigen::Vector3d(0.01, 0.01, 0), Eigen::Vector3d(-0.0, 0.0, 1.0)},
      {o + 0.01 * x, Eigen::Vector3d(0, std::sin(1e-9), std::cos(1e-9))},
      {o + Eigen::Vector3d(0.0, -0.0, 0.01), x}};
  for (const OrientedPoint& b : partners) {
    for (int l = 0; l < 4; ++l) pairs.push_back({{o, z}, b});
  }
  // Every angle of the theta feature's bin edges, by turning the partner's normal about the line.
  for (int k = 0; k <= 11; ++k) {
    for (double eps : {0.0, 1e-12, -1e-12, 1e-7, -1e-7, 1e-5, -1e-5}) {
      const double angle = -M_PI + 2.0 * M_PI * k / 11.0 + eps;
      const Eigen::Vector3d n(0, std::cos(angle), std::sin(angle));
      pairs.push_back({{o, z}, {o + 0.01 * x, n}});
    }
  }
  while (pairs.size() % 4 != 0) pairs.push_back(pairs.back());
  expectSameBins(pairs);
}

}  // namespace
}  // namespace pnpba
