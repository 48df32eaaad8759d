#include "rgbd_residuals.h"

#include <oneapi/tbb/parallel_for.h>
#include <oneapi/tbb/parallel_invoke.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <new>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>
#include <utility>

#include "kth_smallest.h"
#include "nearest_pixel.h"
#include "pnpba/core/error.h"

namespace pnpba {

namespace {

// Writes into *out, reusing its buffer when the size matches.
void metres(const cv::Mat& depth, double depth_scale, cv::Mat* out) {
  depth.convertTo(*out, CV_32F, 1.0 / depth_scale);
}

void gradients(RgbdLevel* l) {
  cv::Sobel(l->grey2, l->gx2, CV_32F, 1, 0, 3, 1.0 / 8.0);
  cv::Sobel(l->grey2, l->gy2, CV_32F, 0, 1, 3, 1.0 / 8.0);
  l->gradients_ready = true;
}

// Bilinear interpolation at (u, v) >= 0: its cell and weights, found once for every float image
// read there (image 2's intensity and its two gradients).
struct BilinearAt {
  BilinearAt(double u, double v)
      : x(static_cast<int>(u)),
        y(static_cast<int>(v)),
        a(static_cast<float>(u - x)),
        b(static_cast<float>(v - y)) {}
  float of(const cv::Mat& m) const {
    const float* r0 = m.ptr<float>(y);
    const float* r1 = m.ptr<float>(y + 1);
    return (1 - b) * ((1 - a) * r0[x] + a * r0[x + 1]) + b * ((1 - a) * r1[x] + a * r1[x + 1]);
  }
  int x, y;
  float a, b;
};

// x rounded to float and back. Through a volatile float: GCC 12's vectoriser drops the round
// trip of two neighbouring conversions at -O2 and above (Eigen's cast<float>().cast<double>() of
// a Vector3d kept only z's rounding, measured), so an optimised build's surfaces differed from a
// debug build's in their last bits.
double throughFloat(double x) {
  volatile float f = static_cast<float>(x);
  return f;
}

Eigen::Vector3d throughFloat(const Eigen::Vector3d& v) {
  return {throughFloat(v.x()), throughFloat(v.y()), throughFloat(v.z())};
}

}  // namespace

SurfaceCache& SurfaceCache::operator=(const SurfaceCache&) {
  cols_ = rows_ = 0;  // holds nothing, as a copy
  return *this;
}

SurfaceCache& SurfaceCache::operator=(SurfaceCache&& other) noexcept {
  cols_ = std::exchange(other.cols_, 0);
  rows_ = std::exchange(other.rows_, 0);
  capacity_ = std::exchange(other.capacity_, 0);
  generation_ = std::exchange(other.generation_, 0);
  block_ = std::move(other.block_);
  entries_ = std::exchange(other.entries_, nullptr);
  return *this;
}

void SurfaceCache::reset(int cols, int rows) {
  const size_t pixels = static_cast<size_t>(cols) * static_cast<size_t>(rows);
  cols_ = cols, rows_ = rows;
  ++generation_;
  if (pixels > capacity_ || generation_ >= (1u << 30)) {
    // Zeroed states are generation 0's, never a current one. The block's pages come zeroed
    // without being written, so a level's cache costs the pages its looks touch: writing zeros
    // into all of them (10 MB at 640 x 480) was most of a new process's first alignment (the
    // textbook pair's depth cross-check 14-19 ms there, 1.7 ms in a warm one).
    block_ = ZeroedBlock();
    block_ = ZeroedBlock(pixels * sizeof(Entry));
    entries_ = std::launder(static_cast<Entry*>(block_.data()));
    capacity_ = pixels;
    generation_ = 1;
  }
}

namespace {

// Depth 2's surface at an inner pixel (x, y) of a level, from its depths.
bool surfaceFromDepth(const RgbdLevel& l, int x, int y, Eigen::Vector3d* P, Eigen::Vector3d* n) {
  const int s = l.normal_step;
  const cv::Mat& depth = l.depth2;
  auto point = [&](int u, int v) {
    const double z = depth.at<float>(v, u);
    return Eigen::Vector3d(l.x_of[u] * z, l.y_of[v] * z, z);
  };
  const float z = depth.at<float>(y, x);
  if (!(z > 0)) return false;
  const float edge = 0.05f + 0.02f * z;
  for (float q : {depth.at<float>(y, x - s), depth.at<float>(y, x + s), depth.at<float>(y - s, x),
                  depth.at<float>(y + s, x)}) {
    if (!(q > 0 && std::abs(q - z) <= edge)) return false;
  }
  const Eigen::Vector3d centre = point(x, y);
  Eigen::Vector3d normal =
      (point(x + s, y) - point(x - s, y)).cross(point(x, y + s) - point(x, y - s));
  const double norm = normal.norm();
  if (!(norm > 0)) return false;
  normal *= 1.0 / norm;
  if (normal.dot(centre) > 0) normal = -normal;
  *n = throughFloat(normal);
  if (n->isZero(0)) return false;
  *P = throughFloat(centre);
  return true;
}

}  // namespace

// Computed where a residual looks, not for every pixel (a full-resolution evaluation looks at
// about one pixel in 16), and kept where it was computed (the level's SurfaceCache).
bool depthSurfaceAt(const RgbdLevel& l, int x, int y, Eigen::Vector3d* P, Eigen::Vector3d* n) {
  const int s = l.normal_step;
  const cv::Mat& depth = l.depth2;
  if (x < s || y < s || x + s >= depth.cols || y + s >= depth.rows) return false;
  auto compute = [&](Eigen::Vector3d* P_, Eigen::Vector3d* n_) {
    return surfaceFromDepth(l, x, y, P_, n_);
  };
  if (!l.surfaces.covers(depth.cols, depth.rows)) return compute(P, n);
  return l.surfaces.at(static_cast<size_t>(y) * depth.cols + x, compute, P, n);
}

namespace {

// backProject's normalised coordinates per column and per row (the same arithmetic, so the same
// points).
void backProjectionTables(RgbdLevel* l) {
  l->x_of.resize(l->depth2.cols);
  l->y_of.resize(l->depth2.rows);
  for (int u = 0; u < l->depth2.cols; ++u) l->x_of[u] = (u - l->camera.cx) / l->camera.fx;
  for (int v = 0; v < l->depth2.rows; ++v) l->y_of[v] = (v - l->camera.cy) / l->camera.fy;
}

}  // namespace

std::vector<RgbdLevel> rgbdPyramid(const cv::Mat& image1, const cv::Mat& depth1,
                                   const cv::Mat& image2, const cv::Mat& depth2,
                                   const PinholeCamera& camera, double depth_scale, int levels) {
  std::vector<RgbdLevel> out;
  rgbdPyramidInto(image1, depth1, image2, depth2, camera, depth_scale, levels, &out);
  prepareFullResolution(&out);
  return out;
}

namespace {

template <typename T>
void everySecondOf(const cv::Mat& m, cv::Mat* out) {
  for (int v = 0; v < out->rows; ++v) {
    const T* in = m.ptr<T>(2 * v);
    T* row = out->ptr<T>(v);
    for (int u = 0; u < out->cols; ++u) row[u] = in[2 * u];
  }
}

}  // namespace

void greyFloat(const cv::Mat& image, cv::Mat* scratch, cv::Mat* out) {
  if (image.channels() == 3) {
    cv::cvtColor(image, *scratch, cv::COLOR_BGR2GRAY);
    scratch->convertTo(*out, CV_32F);
  } else {
    image.convertTo(*out, CV_32F);
  }
}

void everySecondPixel(const cv::Mat& m, cv::Mat* out) {
  out->create(m.rows / 2, m.cols / 2, m.type());
  if (m.type() == CV_32FC1) {
    everySecondOf<float>(m, out);
  } else if (m.type() == CV_16UC1) {
    everySecondOf<uint16_t>(m, out);
  } else {
    throw std::invalid_argument("everySecondPixel: a CV_32FC1 or CV_16UC1 image");
  }
}

PinholeCamera halvedCamera(PinholeCamera camera, int halvings) {
  // Distortion coefficients act on normalised coordinates: a scaled image keeps them.
  for (int i = 0; i < halvings; ++i) {
    camera.fx /= 2, camera.fy /= 2, camera.cx /= 2, camera.cy /= 2;
  }
  return camera;
}

void prepareFullResolution(std::vector<RgbdLevel>* pyramid) {
  if (!pyramid->empty() && !(*pyramid)[0].gradients_ready) gradients(&(*pyramid)[0]);
}

void rgbdPyramidInto(const cv::Mat& image1, const cv::Mat& depth1, const cv::Mat& image2,
                     const cv::Mat& depth2, const PinholeCamera& camera, double depth_scale,
                     int levels, std::vector<RgbdLevel>* pyramid) {
  // A sample reads all four images at one pixel (and back-projects with image 2's tables).
  for (const cv::Mat* m : {&depth1, &image2, &depth2}) {
    if (m->size() != image1.size()) {
      throw Error("rgbd alignment: the colour and depth images differ in size (" +
                  std::to_string(image1.cols) + "x" + std::to_string(image1.rows) + " and " +
                  std::to_string(m->cols) + "x" + std::to_string(m->rows) + ")");
    }
  }
  // Each level halves the last; the pyramid stops before an image narrower than 40 pixels.
  int count = 1;
  for (int cols = image1.cols, rows = image1.rows; count < levels && cols >= 40 && rows >= 40;
       cols /= 2, rows /= 2) {
    ++count;  // (cols, rows): the size of level count - 1, from which level count is made
  }
  std::vector<RgbdLevel>& out = *pyramid;
  out.resize(count);
  out[0].camera = camera;
  out[0].camera.distortion = {};
  out[0].normal_step = 2;
  for (int i = 1; i < count; ++i) {
    // pyrDown's pixel u' and the depth's every second pixel sit on the finer pixel 2 u'.
    out[i].camera = halvedCamera(out[i - 1].camera, 1);
    out[i].normal_step = 1;
  }
  // Frame 1's images and frame 2's (with their gradients) side by side on TBB's workers (as the
  // ORB pair: orb_features.cpp): the two sides share nothing, and each is computed as before.
  auto frame1 = [&] {
    cv::Mat scratch;
    greyFloat(image1, &scratch, &out[0].grey1);
    metres(depth1, depth_scale, &out[0].depth1);
    for (int i = 1; i < count; ++i) {
      const cv::Mat& up = out[i - 1].grey1;
      cv::pyrDown(up, out[i].grey1, cv::Size(up.cols / 2, up.rows / 2));
      everySecondPixel(out[i - 1].depth1, &out[i].depth1);
    }
  };
  auto frame2 = [&] {
    cv::Mat scratch;
    greyFloat(image2, &scratch, &out[0].grey2);
    metres(depth2, depth_scale, &out[0].depth2);
    out[0].gradients_ready = false;  // prepareFullResolution
    backProjectionTables(&out[0]);
    out[0].surfaces.reset(out[0].depth2.cols, out[0].depth2.rows);
    for (int i = 1; i < count; ++i) {
      const cv::Mat& up = out[i - 1].grey2;
      cv::pyrDown(up, out[i].grey2, cv::Size(up.cols / 2, up.rows / 2));
      everySecondPixel(out[i - 1].depth2, &out[i].depth2);
      gradients(&out[i]);
      backProjectionTables(&out[i]);
      out[i].surfaces.reset(out[i].depth2.cols, out[i].depth2.rows);
    }
  };
  tbb::parallel_invoke(frame1, frame2);
}

namespace {
thread_local std::vector<RgbdLevel> spare_pyramid;
}  // namespace

RecycledPyramid::RecycledPyramid() : levels(std::move(spare_pyramid)) { spare_pyramid.clear(); }

RecycledPyramid::~RecycledPyramid() { spare_pyramid = std::move(levels); }

namespace {

// Where a frame-1 sample lands in frame 2 (the first of denseResidualRows' two passes).
struct LandedSample {
  int u;
  Eigen::Vector3d X;  // in camera 2
  double iz;          // 1 / X.z()
  Eigen::Vector2d uv;
  int px, py;  // uv's nearest pixel: where depth 2's surface is looked up
};

// The residuals of the sampled frame-1 rows [v_begin, v_end), appended to out in pixel order.
// Each row in two passes, as the depth consistency's: first where every sample lands in frame 2,
// asking ahead for the lines its look will read (depth 2's surface entry and the depth rows
// around it, image 2's and its gradients' two rows); then the residuals. The looks land all over
// images larger than the cache; a row's requests overlap their misses. Over fr3_cabinet's
// evaluations, timed both ways in one process with the same residuals: 18 % less time (the
// surface entries alone 11 %, the images alone 1 %, the two passes without the requests
// nothing), and 4 % more with the depth rows.
void denseResidualRows(const RgbdLevel& l, const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                       const DenseResidualOptions& o, bool with_details, int v_begin, int v_end,
                       DenseResiduals* out) {
  const PinholeCamera& k = l.camera;
  const int margin = std::max(2, l.normal_step);
  const size_t expected = static_cast<size_t>((v_end - v_begin) / o.stride + 1) *
                          static_cast<size_t>(l.depth1.cols / o.stride + 1);
  out->geometric.reserve(expected);
  out->photometric.reserve(expected);
  const bool surfaces_cached = l.surfaces.covers(l.depth2.cols, l.depth2.rows);
  thread_local std::vector<LandedSample> landed;
  for (int v = v_begin; v < v_end; v += o.stride) {
    const float* depth_row = l.depth1.ptr<float>(v);
    landed.clear();
    for (int u = o.stride / 2; u < l.depth1.cols; u += o.stride) {
      const float z1 = depth_row[u];
      if (!(z1 > 0)) continue;
      ++out->depth1_samples;
      // k.backProject((u, v), z1) from the level's tables: the same arithmetic, two divisions
      // fewer per sample (both images share the level's camera and size).
      const double z = z1;
      const Eigen::Vector3d X = R * Eigen::Vector3d(l.x_of[u] * z, l.y_of[v] * z, z) + t;
      if (X.z() < 0.1) continue;
      const double iz = 1.0 / X.z();  // k.project(X) and its Jacobian with one division
      const Eigen::Vector2d uv(k.fx * X.x() * iz + k.cx, k.fy * X.y() * iz + k.cy);
      if (!(uv.x() >= margin && uv.y() >= margin && uv.x() < l.depth2.cols - margin - 1 &&
            uv.y() < l.depth2.rows - margin - 1)) {
        continue;
      }
      // The surface's pixel: its entry, and the depth rows a surface not yet computed reads.
      const int px = nearestPixel(uv.x()), py = nearestPixel(uv.y());
      if (surfaces_cached) l.surfaces.prefetch(static_cast<size_t>(py) * l.depth2.cols + px);
      for (int dy : {-l.normal_step, 0, l.normal_step}) {
        __builtin_prefetch(l.depth2.ptr<float>(py + dy) + px);
      }
      const int x = static_cast<int>(uv.x()), y = static_cast<int>(uv.y());  // BilinearAt's cell
      for (const cv::Mat* image : {&l.grey2, &l.gx2, &l.gy2}) {
        __builtin_prefetch(image->ptr<float>(y) + x);
        __builtin_prefetch(image->ptr<float>(y + 1) + x);
      }
      landed.push_back({u, X, iz, uv, px, py});
    }
    for (const LandedSample& s : landed) {
      const Eigen::Vector3d& X = s.X;
      Eigen::Vector3d P, n;
      if (!depthSurfaceAt(l, s.px, s.py, &P, &n)) continue;
      const double kz2 = o.depth_noise_k * P.z() * P.z();
      if (std::abs(X.z() - P.z()) > o.visibility_tolerances * (0.02 + 2.0 * kz2)) continue;
      // One division a sample where there were seven.
      const double inv_sigma = 1.0 / (o.depth_noise_floor_m + kz2);
      // Each written in place: a residual built on the stack was stored 8 bytes at a time and
      // copied 16 at a time, which stalled the copy on the stores.
      DenseResidual& geometric = out->geometric.emplace_back();
      geometric.value = n.dot(X - P) * inv_sigma;
      geometric.i1 = 0.0;
      geometric.J = planeJacobian(n, X, inv_sigma);
      const BilinearAt at(s.uv.x(), s.uv.y());
      const double gx = at.of(l.gx2), gy = at.of(l.gy2);
      const double i1 = l.grey1.at<float>(v, s.u), i2 = at.of(l.grey2);
      DenseResidual& photometric = out->photometric.emplace_back();
      photometric.value = i2 - i1;
      photometric.i1 = i1;
      photometric.J = photometricJacobian(k, gx, gy, X, s.iz);
      if (with_details) {
        out->intensity1.push_back(i1);
        out->intensity2.push_back(i2);
        out->pixels1.emplace_back(s.u, v);
      }
    }
  }
}

template <typename T>
void append(std::vector<T>* to, const std::vector<T>& from) {
  to->insert(to->end(), from.begin(), from.end());
}

}  // namespace

void clear(DenseResiduals* r) {
  r->geometric.clear();
  r->photometric.clear();
  r->intensity1.clear();
  r->intensity2.clear();
  r->pixels1.clear();
  r->depth1_samples = 0;
}

int denseResidualBands(const RgbdLevel& l, const SE3Quat& T_21, const DenseResidualOptions& o,
                       bool with_details, DenseResidualWorkspace* workspace) {
  if (!l.gradients_ready) throw Error("dense residuals: the level's gradients were not prepared");
  const Eigen::Matrix3d R = T_21.rotation().toRotationMatrix();
  const Eigen::Vector3d t = T_21.translation();
  // The sampled rows are cut into a fixed number of bands, computed on all cores and joined in
  // row order: the residuals, and everything summed over them, are those of one thread, for any
  // thread count (a full-resolution evaluation is 2-4 ms on one core, several per alignment).
  // TBB, not OpenMP: OpenMP's idle workers spin after each loop and took a core from the next
  // stage (the next pair's ORB ran at half speed after an alignment). Each band is a task that
  // whichever core is free takes: a real depth image's halves seldom hold the same number of
  // depths (the real cabinet's evaluations, alternating in one process: 78 us a call with the
  // bands dealt out in two halves, 73 so).
  constexpr int kBands = 16;
  const int first = o.stride / 2;
  const int sampled_rows = first < l.depth1.rows ? (l.depth1.rows - 1 - first) / o.stride + 1 : 0;
  const int bands = std::max(1, std::min(kBands, sampled_rows / 4));
  std::vector<DenseResiduals>& band = workspace->bands;
  if (static_cast<int>(band.size()) < bands) band.resize(bands);
  tbb::parallel_for(
      0, bands,
      [&](int b) {
        const int row_begin = first + o.stride * (sampled_rows * b / bands);
        const int row_end = first + o.stride * (sampled_rows * (b + 1) / bands);
        clear(&band[b]);
        denseResidualRows(l, R, t, o, with_details, row_begin, std::min(row_end, l.depth1.rows),
                          &band[b]);
      },
      tbb::simple_partitioner());
  return bands;
}

void denseResiduals(const RgbdLevel& l, const SE3Quat& T_21, const DenseResidualOptions& o,
                    bool with_details, DenseResidualWorkspace* workspace, DenseResiduals* out) {
  const int bands = denseResidualBands(l, T_21, o, with_details, workspace);
  const std::vector<DenseResiduals>& band = workspace->bands;
  clear(out);
  for (int b = 0; b < bands; ++b) {
    append(&out->geometric, band[b].geometric);
    append(&out->photometric, band[b].photometric);
    append(&out->intensity1, band[b].intensity1);
    append(&out->intensity2, band[b].intensity2);
    append(&out->pixels1, band[b].pixels1);
    out->depth1_samples += band[b].depth1_samples;
  }
}

DenseResiduals denseResiduals(const RgbdLevel& l, const SE3Quat& T_21,
                              const DenseResidualOptions& o, bool with_details) {
  DenseResidualWorkspace workspace;
  DenseResiduals out;
  denseResiduals(l, T_21, o, with_details, &workspace, &out);
  return out;
}

double medianInPlace(std::vector<double>* values) {
  if (values->empty()) return 0;
  return kthSmallest(values, values->size() / 2);
}

double median(std::vector<double> v) { return medianInPlace(&v); }

double robustSigmaOf(std::vector<double>* deviations, double floor) {
  if (deviations->empty()) return floor;
  return std::max(1.4826 * medianInPlace(deviations), floor);
}

double robustSigma(const std::vector<DenseResidual>& residuals, double floor, double offset) {
  std::vector<double> a;
  a.reserve(residuals.size());
  for (const DenseResidual& r : residuals) a.push_back(std::abs(r.value - offset));
  return robustSigmaOf(&a, floor);
}

}  // namespace pnpba
