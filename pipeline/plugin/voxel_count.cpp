#include "voxel_count.h"

#include <cmath>
#include <cstdint>
#include <set>
#include <tuple>

namespace pnpba {

namespace {

// A voxel's three indices in one key, 21 bits each: any grid up to two million voxels a side.
constexpr int kBits = 21;
constexpr int kLimit = 1 << kBits;

// Open3D's voxel index, operation for operation ((p - origin) / voxel, floor, int), so that a
// point on a voxel's boundary falls where VoxelDownSample puts it.
Eigen::Vector3i voxelIndex(const Eigen::Vector3d& p, const Eigen::Vector3d& origin, double voxel) {
  const Eigen::Vector3d ref = (p - origin) / voxel;
  return {static_cast<int>(std::floor(ref(0))), static_cast<int>(std::floor(ref(1))),
          static_cast<int>(std::floor(ref(2)))};
}

// Distinct keys by open addressing on key + 1 (0 marks an empty slot), the table at least twice
// the keys.
size_t countDistinct(const std::vector<uint64_t>& keys) {
  size_t size = 16;
  while (size < 2 * keys.size()) size *= 2;
  std::vector<uint64_t> table(size, 0);
  const size_t mask = size - 1;
  size_t distinct = 0;
  for (const uint64_t key : keys) {
    const uint64_t stored = key + 1;
    // Fibonacci hashing: neighbouring voxels differ in the key's low bits, the product spreads
    // them.
    size_t slot = static_cast<size_t>((stored * 0x9E3779B97F4A7C15ULL) >> 32) & mask;
    while (table[slot] != 0 && table[slot] != stored) slot = (slot + 1) & mask;
    if (table[slot] == 0) {
      table[slot] = stored;
      ++distinct;
    }
  }
  return distinct;
}

}  // namespace

size_t occupiedVoxels(const std::vector<Eigen::Vector3d>& points, double voxel) {
  if (points.empty()) return 0;
  Eigen::Vector3d least = points.front();
  for (const Eigen::Vector3d& p : points) least = least.cwiseMin(p);
  // Open3D's origin: GetMinBound() - (voxel, voxel, voxel) * 0.5.
  const Eigen::Vector3d origin = least - Eigen::Vector3d::Constant(voxel) * 0.5;
  std::vector<uint64_t> keys;
  keys.reserve(points.size());
  bool fits = true;
  for (const Eigen::Vector3d& p : points) {
    const Eigen::Vector3i i = voxelIndex(p, origin, voxel);
    // The origin lies below every point, so the indices start at 0 (a voxel so small that the
    // cloud spans more than the key holds is counted below instead).
    if ((i.array() < 0).any() || (i.array() >= kLimit).any()) {
      fits = false;
      break;
    }
    keys.push_back((static_cast<uint64_t>(i(0)) << (2 * kBits)) |
                   (static_cast<uint64_t>(i(1)) << kBits) | static_cast<uint64_t>(i(2)));
  }
  if (fits) return countDistinct(keys);
  std::set<std::tuple<int, int, int>> seen;
  for (const Eigen::Vector3d& p : points) {
    const Eigen::Vector3i i = voxelIndex(p, origin, voxel);
    seen.emplace(i(0), i(1), i(2));
  }
  return seen.size();
}

}  // namespace pnpba
