#include "voxel_grid.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <set>
#include <tuple>
#include <utility>

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

// The voxels' keys, one per point, where every index fits kBits (the origin lies below every
// point, so the indices start at 0); false for a voxel so small that the cloud spans more.
bool voxelKeys(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& origin,
               double voxel, std::vector<uint64_t>* keys) {
  keys->clear();
  keys->reserve(points.size());
  for (const Eigen::Vector3d& p : points) {
    const Eigen::Vector3i i = voxelIndex(p, origin, voxel);
    if ((i.array() < 0).any() || (i.array() >= kLimit).any()) return false;
    keys->push_back((static_cast<uint64_t>(i(0)) << (2 * kBits)) |
                    (static_cast<uint64_t>(i(1)) << kBits) | static_cast<uint64_t>(i(2)));
  }
  return true;
}

// Open3D's origin: the points' least corner less half a voxel.
Eigen::Vector3d gridOrigin(const std::vector<Eigen::Vector3d>& points, double voxel) {
  Eigen::Vector3d least = points.front();
  for (const Eigen::Vector3d& p : points) least = least.cwiseMin(p);
  return least - Eigen::Vector3d::Constant(voxel) * 0.5;
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

// A voxel's three indices combined as boost::hash_combine combines values, each hashed by
// std::hash<int>: the hash Open3D's VoxelDownSample keys its table with.
struct VoxelIndexHash {
  size_t operator()(const Eigen::Vector3i& index) const {
    size_t seed = 0;
    for (int axis = 0; axis < 3; ++axis) {
      seed ^= std::hash<int>()(index(axis)) + 0x9e3779b9 + (seed << 6) + (seed >> 2);
    }
    return seed;
  }
};

// Every point's voxel number in the order a std::unordered_map keyed by VoxelIndexHash, filled
// in the points' order, lists the voxels: Open3D's order, so that the registration sees the
// clouds it saw when Open3D down-sampled them (which neighbour a point keeps where distances tie
// follows it). Returns the count.
size_t numberVoxelsAsOpen3d(const std::vector<Eigen::Vector3d>& points, double voxel,
                            std::vector<int>* numbers) {
  if (points.empty()) return 0;
  const Eigen::Vector3d origin = gridOrigin(points, voxel);
  std::vector<Eigen::Vector3i> indices(points.size());
  std::unordered_map<Eigen::Vector3i, int, VoxelIndexHash> places;
  for (size_t k = 0; k < points.size(); ++k) {
    indices[k] = voxelIndex(points[k], origin, voxel);
    places.try_emplace(indices[k], 0);
  }
  int next = 0;
  for (auto& entry : places) entry.second = next++;
  numbers->resize(points.size());
  for (size_t k = 0; k < points.size(); ++k) (*numbers)[k] = places.at(indices[k]);
  return places.size();
}

// Each voxel's mean of `values` (one per point), summed in the points' order.
std::vector<Eigen::Vector3d> voxelMeans(const std::vector<Eigen::Vector3d>& values,
                                        const std::vector<int>& numbers, size_t voxels) {
  std::vector<Eigen::Vector3d> sums(voxels, Eigen::Vector3d::Zero());
  std::vector<int> counts(voxels, 0);
  for (size_t k = 0; k < values.size(); ++k) {
    sums[numbers[k]] += values[k];
    ++counts[numbers[k]];
  }
  for (size_t v = 0; v < voxels; ++v) sums[v] /= static_cast<double>(counts[v]);
  return sums;
}

}  // namespace

size_t occupiedVoxels(const std::vector<Eigen::Vector3d>& points, double voxel) {
  if (points.empty()) return 0;
  const Eigen::Vector3d origin = gridOrigin(points, voxel);
  std::vector<uint64_t> keys;
  if (voxelKeys(points, origin, voxel, &keys)) return countDistinct(keys);
  // A voxel so small that the cloud spans more than the key holds: an ordered set.
  std::set<std::tuple<int, int, int>> seen;
  for (const Eigen::Vector3d& p : points) {
    const Eigen::Vector3i i = voxelIndex(p, origin, voxel);
    seen.emplace(i(0), i(1), i(2));
  }
  return seen.size();
}

Cloud voxelDownSample(const Cloud& cloud, double voxel) {
  std::vector<int> numbers;
  const size_t voxels = numberVoxelsAsOpen3d(cloud.points, voxel, &numbers);
  Cloud out;
  out.points = voxelMeans(cloud.points, numbers, voxels);
  if (cloud.normals.size() == cloud.points.size() && !cloud.points.empty()) {
    out.normals = voxelMeans(cloud.normals, numbers, voxels);
  }
  return out;
}

}  // namespace pnpba
