// Private to the pipeline: the dense residuals of a pose between two RGB-D frames, shared by
// the direct RGB-D alignment (rgbd_alignment.h) and the alignment evidence
// (alignment_evidence.h). For each sampled frame-1 pixel with depth, X = T_21 X_1 lands at
// pixel uv in frame 2 and gives
//   photometric  I_2(uv) - I_1(u_1)                  (intensity units; bias not removed)
//   geometric    n . (X - P) / (floor + k z^2)       (P, n: depth 2's surface at uv)
// with their Jacobians for the left perturbation T <- exp(d) T, d = [w, v].
#pragma once

#include <Eigen/Core>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>
#include <utility>
#include <vector>

#include "pnpba/features/pinhole_camera.h"
#include "pnpba/optimize/projection_jacobians.h"
#include "pnpba/optimize/se3_quat.h"
#include "pnpba/pipeline/alignment_evidence.h"
#include "pnpba/pipeline/rgbd_alignment.h"
#include "zeroed_block.h"

namespace pnpba {

// Depth 2's surfaces (depthSurfaceAt) kept per pixel of a level for one pair. An alignment looks
// at the same frame-2 pixels iteration after iteration, and the depth path aligns several
// candidates over the same pair: on the rendered poor room each pixel was looked at 4-8 times
// (648 000 looks at 131 000 pixels on its slowest pair). Safe to fill from several threads: a
// pixel is computed by the first thread to claim it and by any thread that finds it being
// computed, so every look returns what depthSurfaceAt computes, bit for bit (its coordinates
// are float's, and held as floats). A copy holds nothing; reset() forgets every pixel without
// touching them (a generation count), and keeps its memory for the next pair.
class SurfaceCache {
 public:
  SurfaceCache() = default;
  SurfaceCache(const SurfaceCache&) {}
  SurfaceCache& operator=(const SurfaceCache&);
  SurfaceCache(SurfaceCache&& other) noexcept { *this = std::move(other); }
  SurfaceCache& operator=(SurfaceCache&& other) noexcept;  // `other` is left empty

  void reset(int cols, int rows);  // a level of this size, every pixel unknown
  // Asks for pixel i's entry ahead of its look (a hint; nothing changes).
  void prefetch(size_t i) const { __builtin_prefetch(entries_ + i); }
  bool covers(int cols, int rows) const { return cols == cols_ && rows == rows_; }
  // The surface at pixel index i (row-major), computed by compute(P, n) where not known yet.
  template <typename Compute>
  bool at(size_t i, const Compute& compute, Eigen::Vector3d* P, Eigen::Vector3d* n);

 private:
  enum : uint32_t { kComputing = 0, kValid = 1, kNone = 2 };  // low two bits; the rest: generation
  int cols_ = 0, rows_ = 0;
  size_t capacity_ = 0;
  uint32_t generation_ = 0;
  // A pixel's state beside its surface in one 32-byte entry: a look reads one cache line where
  // separate state and value arrays cost it two misses. All-zero bytes are an entry of
  // generation 0, never a current one.
  struct alignas(32) Entry {
    std::atomic<uint32_t> state;
    float values[6];  // P then n
  };
  ZeroedBlock block_;         // zeroed by the system, not written (zeroed_block.h)
  Entry* entries_ = nullptr;  // in block_
};

// One pyramid level of the pair.
struct RgbdLevel {
  cv::Mat grey1, grey2, gx2, gy2;  // CV_32F; gradients of image 2 per pixel
  bool gradients_ready = false;    // gx2, gy2 hold this pair's gradients
  cv::Mat depth1, depth2;          // CV_32F metres, 0 = no depth
  PinholeCamera camera;            // scaled to the level
  int normal_step = 2;             // neighbour distance of depth-2 normals (pixels)
  // (u - cx) / fx per column and (v - cy) / fy per row: the sampled depth-1 pixels and depth 2's
  // points where a residual looks, back-projected without a division.
  std::vector<double> x_of, y_of;
  mutable SurfaceCache surfaces;  // depth 2's, filled as residuals look (reset with depth2)
};

// An image's grey in floats: a colour one's as OpenCV's grey in whole numbers (through *scratch),
// a grey one as it is. Writes into *out, reusing its buffer when the size matches.
void greyFloat(const cv::Mat& image, cv::Mat* scratch, cv::Mat* out);
// An image halved as the pyramid halves depth: every second pixel of every second row, pixel u'
// on the finer 2 u' (averaging would blend surfaces at depth edges). CV_32FC1 or CV_16UC1;
// written into *out's memory where its size matches.
void everySecondPixel(const cv::Mat& m, cv::Mat* out);
// The pinhole of an image halved `halvings` times so (and its colour by cv::pyrDown).
PinholeCamera halvedCamera(PinholeCamera camera, int halvings);

// Level 0 at full resolution, each next at half (images: cv::pyrDown; depths: everySecondPixel).
std::vector<RgbdLevel> rgbdPyramid(const cv::Mat& image1, const cv::Mat& depth1,
                                   const cv::Mat& image2, const cv::Mat& depth2,
                                   const PinholeCamera& camera, double depth_scale, int levels);
// The same, written into the images *pyramid already holds where their sizes match (no fresh
// memory); *pyramid's Mats must not be shared. Level 0's gradients are left to
// prepareFullResolution: a confirmation at quarter resolution never needs them.
void rgbdPyramidInto(const cv::Mat& image1, const cv::Mat& depth1, const cv::Mat& image2,
                     const cv::Mat& depth2, const PinholeCamera& camera, double depth_scale,
                     int levels, std::vector<RgbdLevel>* pyramid);
// Computes level 0's gradients if they are not there yet (0.3-0.4 ms at 640 x 480).
void prepareFullResolution(std::vector<RgbdLevel>* pyramid);

// A pyramid whose buffers outlive it on its thread: it starts with the buffers the last one on
// this thread left (one pyramid's, about 10 MB at 640 x 480, and its kept surfaces' 11 MB) and
// leaves its own. Fresh memory of that size cost 2 ms of page faults per pair (the textbook
// pair's pyramid: 2.8 -> 0.8 ms).
class RecycledPyramid {
 public:
  RecycledPyramid();
  ~RecycledPyramid();
  RecycledPyramid(const RecycledPyramid&) = delete;
  RecycledPyramid& operator=(const RecycledPyramid&) = delete;

  std::vector<RgbdLevel> levels;
  bool built = false;  // rgbdPyramidInto has written `levels` for this pair
};

// Depth 2's surface at pixel (x, y) of a level: its point and unit normal facing the camera, from
// the neighbours normal_step pixels away, each coordinate rounded to float as a per-pixel
// surface image would hold it; false at holes, depth edges and the border.
bool depthSurfaceAt(const RgbdLevel& level, int x, int y, Eigen::Vector3d* P, Eigen::Vector3d* n);

struct DenseResidual {
  double value;
  // Photometric: I_1(u_1), which a brightness change scales (brightness_change.h); 0 for the
  // geometric ones. Before J, in the 8 bytes J's 16-byte alignment leaves after `value`: a
  // residual stays 64 bytes at SSE's alignment (80 with it after J).
  double i1;
  Eigen::Matrix<double, 1, 6> J;
};

struct DenseResiduals {
  std::vector<DenseResidual> photometric, geometric;
  // With details only, one per sample (the photometric and geometric samples come in pairs):
  std::vector<double> intensity1, intensity2;  // the intensities compared
  std::vector<cv::Point> pixels1;              // the sampled frame-1 pixel
  int depth1_samples = 0;                      // sampled frame-1 pixels with a depth
};

struct DenseResidualOptions {
  int stride = 1;
  double depth_noise_k = 0.003;        // 1/m
  double depth_noise_floor_m = 0.005;  // m
  // Samples whose depth disagrees by more than this many tolerances (2 cm + 2 k z^2) are
  // occluded or unmatched and give no residual.
  double visibility_tolerances = 2.0;
};

// with_details: also fill intensity1, intensity2 and pixels1 (for the alignment evidence).
DenseResiduals denseResiduals(const RgbdLevel& level, const SE3Quat& T_21,
                              const DenseResidualOptions& options, bool with_details = true);

// Storage kept between evaluations (an alignment's iterations): the vectors keep their
// capacity, so that an evaluation does not fault in megabytes of fresh memory each time.
struct DenseResidualWorkspace {
  std::vector<DenseResiduals> bands;
};
// The same into *out, reusing out's and the workspace's storage.
void denseResiduals(const RgbdLevel& level, const SE3Quat& T_21,
                    const DenseResidualOptions& options, bool with_details,
                    DenseResidualWorkspace* workspace, DenseResiduals* out);
// The same left in workspace->bands[0, returned count): band after band, each in pixel order,
// so that a caller that only sums over them in that order (the alignment's iterations) gets the
// joined residuals' sums without copying them.
int denseResidualBands(const RgbdLevel& level, const SE3Quat& T_21,
                       const DenseResidualOptions& options, bool with_details,
                       DenseResidualWorkspace* workspace);

// d(pixel of exp(d) X)/dd at d = 0, [w, v] order, at the camera-frame point X (iz = 1 / X.z(),
// which a caller that projected X already has): the negative of EdgeSE3ProjectXYZ's error
// Jacobian (DESIGN.md 4). Inline: the dense residuals take one per sample.
inline Eigen::Matrix<double, 2, 6> projectionJacobian(const PinholeCamera& k,
                                                      const Eigen::Vector3d& X, double iz) {
  const double x = X.x(), y = X.y(), z = X.z();
  // d(pixel)/dX = [[a, 0, c], [0, e, f]] times d(exp(d) X)/dd = [-[X]x, I] (pointByPoseTangent),
  // its zero products left out: each entry the same sum of the same nonzero products.
  const double a = k.fx * iz, c = -k.fx * x * iz * iz;
  const double e = k.fy * iz, f = -k.fy * y * iz * iz;
  Eigen::Matrix<double, 2, 6> J;
  J << c * y, a * z + c * -x, a * -y, a, 0, c,  //
      e * -z + f * y, f * -x, e * x, 0, e, f;
  return J;
}
inline Eigen::Matrix<double, 2, 6> projectionJacobian(const PinholeCamera& k,
                                                      const Eigen::Vector3d& X) {
  return projectionJacobian(k, X, 1.0 / X.z());
}

// A photometric residual's Jacobian, grad * projectionJacobian(k, X, iz), and a geometric one's,
// n^T pointByPoseTangent(X) inv_sigma, written out entry by entry: each the same products summed
// in the order Eigen's product sums them (zero products included), so the same bits
// (RgbdResiduals.WrittenOutJacobiansMatchTheProducts). Built as matrices and multiplied, the
// compiler stored each matrix an entry at a time and read it back two entries at a time, which
// stalled the load on the stores (perf annotate: half of the dense residuals' samples).
inline Eigen::Matrix<double, 1, 6> photometricJacobian(const PinholeCamera& k, double g0, double g1,
                                                       const Eigen::Vector3d& X, double iz) {
  const double x = X.x(), y = X.y(), z = X.z();
  const double a = k.fx * iz, c = -k.fx * x * iz * iz;
  const double e = k.fy * iz, f = -k.fy * y * iz * iz;
  Eigen::Matrix<double, 1, 6> J;
  J(0) = g0 * (c * y) + g1 * (e * -z + f * y);
  J(1) = g0 * (a * z + c * -x) + g1 * (f * -x);
  J(2) = g0 * (a * -y) + g1 * (e * x);
  J(3) = g0 * a + g1 * 0.0;
  J(4) = g0 * 0.0 + g1 * e;
  J(5) = g0 * c + g1 * f;
  return J;
}
inline Eigen::Matrix<double, 1, 6> planeJacobian(const Eigen::Vector3d& n, const Eigen::Vector3d& X,
                                                 double inv_sigma) {
  const double n0 = n.x(), n1 = n.y(), n2 = n.z();
  Eigen::Matrix<double, 1, 6> J;
  J(0) = ((n0 * 0.0 + n1 * -X.z()) + n2 * X.y()) * inv_sigma;
  J(1) = ((n0 * X.z() + n1 * 0.0) + n2 * -X.x()) * inv_sigma;
  J(2) = ((n0 * -X.y() + n1 * X.x()) + n2 * 0.0) * inv_sigma;
  J(3) = ((n0 * 1.0 + n1 * 0.0) + n2 * 0.0) * inv_sigma;
  J(4) = ((n0 * 0.0 + n1 * 1.0) + n2 * 0.0) * inv_sigma;
  J(5) = ((n0 * 0.0 + n1 * 0.0) + n2 * 1.0) * inv_sigma;
  return J;
}

// The median of v (the upper middle of an even count; 0 for none), in v's own storage.
double median(std::vector<double> v);
// The same of *values, reordering them.
double medianInPlace(std::vector<double>* values);
// 1.4826 times the median of *deviations (absolute deviations, reordered), at least floor.
double robustSigmaOf(std::vector<double>* deviations, double floor);

// 1.4826 times the median of |value - offset| (at least floor).
double robustSigma(const std::vector<DenseResidual>& residuals, double floor, double offset = 0);

// alignRgbd and measureAlignment on a pyramid built once (rgbd_alignment.cpp,
// alignment_evidence.cpp): the depth path aligns several candidates on the same frames. The
// alignment stops, out_of_time, at the first step that would start at or after `deadline`.
RgbdAlignment alignRgbdPyramid(
    const std::vector<RgbdLevel>& pyramid, const PinholeCamera& camera, const SE3Quat& T_seed,
    const std::vector<AlignmentFeature>& features, const RgbdAlignmentOptions& options,
    std::chrono::steady_clock::time_point deadline = std::chrono::steady_clock::time_point::max());
AlignmentEvidence measureAlignmentAt(const RgbdLevel& level0, const PinholeCamera& camera,
                                     const SE3Quat& T_21,
                                     const std::vector<AlignmentFeature>& features,
                                     const AlignmentEvidenceOptions& options);

template <typename Compute>
bool SurfaceCache::at(size_t i, const Compute& compute, Eigen::Vector3d* P, Eigen::Vector3d* n) {
  const uint32_t mine = generation_ << 2;
  Entry& entry = entries_[i];
  uint32_t seen = entry.state.load(std::memory_order_acquire);
  if ((seen & ~3u) == mine) {
    if ((seen & 3u) == kValid) {
      const float* v = entry.values;
      *P = Eigen::Vector3d(v[0], v[1], v[2]);
      *n = Eigen::Vector3d(v[3], v[4], v[5]);
      return true;
    }
    if ((seen & 3u) == kNone) return false;
    return compute(P, n);  // another thread is computing it
  }
  if (!entry.state.compare_exchange_strong(seen, mine | kComputing, std::memory_order_acquire)) {
    return compute(P, n);
  }
  const bool ok = compute(P, n);
  if (ok) {
    float* v = entry.values;
    for (int k = 0; k < 3; ++k)
      v[k] = static_cast<float>((*P)(k)), v[3 + k] = static_cast<float>((*n)(k));
  }
  entry.state.store(mine | (ok ? kValid : kNone), std::memory_order_release);
  return ok;
}

}  // namespace pnpba
