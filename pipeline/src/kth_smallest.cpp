#include "kth_smallest.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>

namespace pnpba {

namespace {

constexpr uint64_t kSignBit = uint64_t{1} << 63;

// An unsigned key per double that orders as the doubles do: a positive double's bits with the
// sign bit set, a negative one's bits flipped (IEEE 754 stores sign and magnitude). -0 becomes +0
// so that equal doubles have equal keys.
inline uint64_t orderKey(double v) {
  uint64_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  if (bits == kSignBit) bits = 0;
  return bits & kSignBit ? ~bits : bits | kSignBit;
}

inline double fromKey(uint64_t key) {
  const uint64_t bits = key & kSignBit ? key & ~kSignBit : ~key;
  double v;
  std::memcpy(&v, &bits, sizeof v);
  return v;
}

// Below this many, nth_element on the keys is as fast as another pass.
constexpr size_t kFew = 48;
// Eight bits a pass: a histogram small enough to clear and scan for a few hundred values.
constexpr int kDigitBits = 8;
constexpr uint64_t kDigits = uint64_t{1} << kDigitBits;

}  // namespace

double kthSmallest(std::vector<double>* values, size_t k) {
  std::vector<double>& v = *values;
  const size_t n = v.size();
  if (n <= 2 * kFew) {
    std::nth_element(v.begin(), v.begin() + k, v.end());
    return v[k] == 0 ? 0.0 : v[k];
  }
  thread_local std::vector<uint64_t> keys;
  keys.resize(n);
  uint64_t low = ~uint64_t{0}, high = 0;
  bool nan = false;
  for (size_t i = 0; i < n; ++i) {
    nan |= v[i] != v[i];
    const uint64_t key = orderKey(v[i]);
    keys[i] = key;
    low = std::min(low, key);
    high = std::max(high, key);
  }
  if (nan) {
    std::nth_element(v.begin(), v.begin() + k, v.end());
    return v[k];
  }
  if (low == high) return fromKey(low);
  // Every key shares the bits above the highest one where the lowest and highest differ. From
  // there down, kDigitBits at a time, the keys left are sorted into buckets by those bits, and
  // only the bucket holding rank k stays (its rank within it carried on), until few are left.
  size_t count = n;
  int shift = std::max(0, 64 - __builtin_clzll(low ^ high) - kDigitBits);
  while (true) {
    // Four histograms, one for every fourth key: the residuals crowd into a few buckets, and
    // one counter's increments in a row would wait on each other through memory.
    std::array<std::array<uint32_t, kDigits>, 4> counts{};
    size_t i = 0;
    for (; i + 4 <= count; i += 4) {
      ++counts[0][(keys[i] >> shift) & (kDigits - 1)];
      ++counts[1][(keys[i + 1] >> shift) & (kDigits - 1)];
      ++counts[2][(keys[i + 2] >> shift) & (kDigits - 1)];
      ++counts[3][(keys[i + 3] >> shift) & (kDigits - 1)];
    }
    for (; i < count; ++i) ++counts[0][(keys[i] >> shift) & (kDigits - 1)];
    uint64_t digit = 0;
    size_t in_bucket = 0;
    for (;; ++digit) {
      in_bucket = counts[0][digit] + counts[1][digit] + counts[2][digit] + counts[3][digit];
      if (k < in_bucket) break;
      k -= in_bucket;
    }
    if (in_bucket < count) {
      size_t kept = 0;
      if (8 * in_bucket < count) {
        // A small bucket: the branch is seldom taken, so it is seldom mispredicted.
        for (i = 0; i < count; ++i) {
          if (((keys[i] >> shift) & (kDigits - 1)) == digit) keys[kept++] = keys[i];
        }
      } else {
        // A large one: every key written, the count advanced only for those in it.
        for (i = 0; i < count; ++i) {
          const uint64_t key = keys[i];
          keys[kept] = key;
          kept += ((key >> shift) & (kDigits - 1)) == digit;
        }
      }
      count = kept;
    }
    if (shift == 0) return fromKey(keys[0]);  // every bit read: the keys left are equal
    if (count <= kFew) break;
    shift = std::max(0, shift - kDigitBits);
  }
  std::nth_element(keys.begin(), keys.begin() + k, keys.begin() + count);
  return fromKey(keys[k]);
}

}  // namespace pnpba
