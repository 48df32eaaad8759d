// OpenCV 4.6's SIFT detection (sift.dispatch.cpp and sift.simd.hpp: its difference of Gaussians,
// findScaleSpaceExtrema, adjustLocalExtrema, calcOrientationHist) in the same float operations
// in the same order. OpenCV's AVX2 build lets the compiler fuse a multiply and an add; the
// functions that compute here are built for AVX2 and FMA with fusing on (CMakeLists.txt), so the
// compiler fuses the same expressions the same way, and the two loops OpenCV writes in vector
// instructions are written in the same ones. sift_detection_test compares every keypoint field
// with OpenCV's detect.
#include "sift_detection.h"

#include <immintrin.h>
#include <oneapi/tbb/parallel_for.h>

#include <cfloat>
#include <climits>
#include <cmath>
#include <opencv2/core/hal/hal.hpp>
#include <opencv2/features2d.hpp>

#include "pnpba/core/error.h"

namespace pnpba {

namespace {

constexpr int kLayers = kSiftOctaveLayers;            // 3 an octave
constexpr int kDogPerOctave = kSiftOctaveLayers + 2;  // differences an octave
constexpr int kBorder = 5;                            // no keypoint this close to the edge
constexpr int kMaxInterpolationSteps = 5;
constexpr int kOrientationBins = 36;
constexpr float kOrientationSigmaFactor = 1.5f;
constexpr float kOrientationRadius = 4.5f;  // 3 sigmas
constexpr float kOrientationPeakRatio = 0.8f;
constexpr float kEdgeThreshold = 10.f;
constexpr float kSigma = 1.6f;
constexpr int kRowsATask = 16;

// Difference of Gaussians: octave o's i-th is its Gaussian i + 1 less its Gaussian i.
std::vector<cv::Mat> differenceOfGaussians(const SiftScaleSpace& space) {
  std::vector<cv::Mat> dog(static_cast<size_t>(space.octaves) * kDogPerOctave);
  tbb::parallel_for(0, static_cast<int>(dog.size()), [&](int a) {
    const int o = a / kDogPerOctave, i = a % kDogPerOctave;
    const cv::Mat& lower = space.images[o * kSiftLayersPerOctave + i];
    const cv::Mat& upper = space.images[o * kSiftLayersPerOctave + i + 1];
    cv::subtract(upper, lower, dog[a], cv::noArray(), CV_32F);
  });
  return dog;
}

// A local extremum of the 3 x 3 x 3 neighbourhood (ties allowed), above the threshold.
bool isExtremum(const float* previous, const float* current, const float* next, int c, int step,
                float threshold) {
  const float value = current[c];
  if (!(std::abs(value) > threshold)) return false;
  const float* rows[3] = {previous, current, next};
  if (value > 0) {
    for (const float* p : rows) {
      for (int offset : {-step, 0, step}) {
        for (int dc = -1; dc <= 1; ++dc) {
          if (!(value >= p[c + offset + dc])) return false;
        }
      }
    }
    return true;
  }
  if (value < 0) {
    for (const float* p : rows) {
      for (int offset : {-step, 0, step}) {
        for (int dc = -1; dc <= 1; ++dc) {
          if (!(value <= p[c + offset + dc])) return false;
        }
      }
    }
    return true;
  }
  return false;
}

// cv::Matx33f::solve(b, DECOMP_LU) for a 3 x 3 system: Cramer's rule with its determinant, as
// OpenCV's header writes them (rounded to float, the determinant computed in float).
__attribute__((target("avx2,fma"))) cv::Vec3f solveByCramer(const cv::Matx33f& a,
                                                            const cv::Vec3f& b) {
  float d =
      static_cast<float>(static_cast<double>(a(0, 0) * (a(1, 1) * a(2, 2) - a(2, 1) * a(1, 2)) -
                                             a(0, 1) * (a(1, 0) * a(2, 2) - a(2, 0) * a(1, 2)) +
                                             a(0, 2) * (a(1, 0) * a(2, 1) - a(2, 0) * a(1, 1))));
  if (d == 0) return cv::Vec3f(0, 0, 0);
  d = 1 / d;
  cv::Vec3f x;
  x(0) = d * (b(0) * (a(1, 1) * a(2, 2) - a(1, 2) * a(2, 1)) -
              a(0, 1) * (b(1) * a(2, 2) - a(1, 2) * b(2)) +
              a(0, 2) * (b(1) * a(2, 1) - a(1, 1) * b(2)));
  x(1) = d * (a(0, 0) * (b(1) * a(2, 2) - a(1, 2) * b(2)) -
              b(0) * (a(1, 0) * a(2, 2) - a(1, 2) * a(2, 0)) +
              a(0, 2) * (a(1, 0) * b(2) - b(1) * a(2, 0)));
  x(2) = d * (a(0, 0) * (a(1, 1) * b(2) - b(1) * a(2, 1)) -
              a(0, 1) * (a(1, 0) * b(2) - b(1) * a(2, 0)) +
              b(0) * (a(1, 0) * a(2, 1) - a(1, 1) * a(2, 0)));
  return x;
}

// An extremum's place and scale to a fraction of a pixel and a layer, by Newton steps on the
// difference of Gaussians; false where it drifts out, does not settle, has too little contrast
// or lies on an edge (Lowe, section 4).
__attribute__((target("avx2,fma"))) bool refineExtremum(const std::vector<cv::Mat>& dog,
                                                        cv::KeyPoint* kpt, int octave, int* layer,
                                                        int* r, int* c, float contrast_threshold) {
  const float image_scale = 1.f / 255;
  const float derivative_scale = image_scale * 0.5f;
  const float second_derivative_scale = image_scale;
  const float cross_derivative_scale = image_scale * 0.25f;
  float xi = 0, xr = 0, xc = 0, contrast = 0;
  int step = 0;
  for (; step < kMaxInterpolationSteps; ++step) {
    const int index = octave * kDogPerOctave + *layer;
    const cv::Mat& img = dog[index];
    const cv::Mat& prev = dog[index - 1];
    const cv::Mat& next = dog[index + 1];
    const int y = *r, x = *c;
    const cv::Vec3f dD((img.at<float>(y, x + 1) - img.at<float>(y, x - 1)) * derivative_scale,
                       (img.at<float>(y + 1, x) - img.at<float>(y - 1, x)) * derivative_scale,
                       (next.at<float>(y, x) - prev.at<float>(y, x)) * derivative_scale);
    const float v2 = img.at<float>(y, x) * 2;
    const float dxx =
        (img.at<float>(y, x + 1) + img.at<float>(y, x - 1) - v2) * second_derivative_scale;
    const float dyy =
        (img.at<float>(y + 1, x) + img.at<float>(y - 1, x) - v2) * second_derivative_scale;
    const float dss = (next.at<float>(y, x) + prev.at<float>(y, x) - v2) * second_derivative_scale;
    const float dxy = (img.at<float>(y + 1, x + 1) - img.at<float>(y + 1, x - 1) -
                       img.at<float>(y - 1, x + 1) + img.at<float>(y - 1, x - 1)) *
                      cross_derivative_scale;
    const float dxs = (next.at<float>(y, x + 1) - next.at<float>(y, x - 1) -
                       prev.at<float>(y, x + 1) + prev.at<float>(y, x - 1)) *
                      cross_derivative_scale;
    const float dys = (next.at<float>(y + 1, x) - next.at<float>(y - 1, x) -
                       prev.at<float>(y + 1, x) + prev.at<float>(y - 1, x)) *
                      cross_derivative_scale;
    const cv::Matx33f H(dxx, dxy, dxs, dxy, dyy, dys, dxs, dys, dss);
    const cv::Vec3f X = solveByCramer(H, dD);
    xi = -X[2];
    xr = -X[1];
    xc = -X[0];
    if (std::abs(xi) < 0.5f && std::abs(xr) < 0.5f && std::abs(xc) < 0.5f) break;
    if (std::abs(xi) > static_cast<float>(INT_MAX / 3) ||
        std::abs(xr) > static_cast<float>(INT_MAX / 3) ||
        std::abs(xc) > static_cast<float>(INT_MAX / 3)) {
      return false;
    }
    *c += cvRound(xc);
    *r += cvRound(xr);
    *layer += cvRound(xi);
    if (*layer < 1 || *layer > kLayers || *c < kBorder || *c >= img.cols - kBorder ||
        *r < kBorder || *r >= img.rows - kBorder) {
      return false;
    }
  }
  if (step >= kMaxInterpolationSteps) return false;

  const int index = octave * kDogPerOctave + *layer;
  const cv::Mat& img = dog[index];
  const cv::Mat& prev = dog[index - 1];
  const cv::Mat& next = dog[index + 1];
  const int y = *r, x = *c;
  const float d0 = (img.at<float>(y, x + 1) - img.at<float>(y, x - 1)) * derivative_scale;
  const float d1 = (img.at<float>(y + 1, x) - img.at<float>(y - 1, x)) * derivative_scale;
  const float d2 = (next.at<float>(y, x) - prev.at<float>(y, x)) * derivative_scale;
  // cv::Matx31f::dot: a running sum from zero.
  float t = 0;
  t += d0 * xc;
  t += d1 * xr;
  t += d2 * xi;
  contrast = img.at<float>(y, x) * image_scale + t * 0.5f;
  if (std::abs(contrast) * kLayers < contrast_threshold) return false;
  // The principal curvatures' ratio, from the trace and determinant of the 2 x 2 Hessian.
  const float v2 = img.at<float>(y, x) * 2.f;
  const float dxx =
      (img.at<float>(y, x + 1) + img.at<float>(y, x - 1) - v2) * second_derivative_scale;
  const float dyy =
      (img.at<float>(y + 1, x) + img.at<float>(y - 1, x) - v2) * second_derivative_scale;
  const float dxy = (img.at<float>(y + 1, x + 1) - img.at<float>(y + 1, x - 1) -
                     img.at<float>(y - 1, x + 1) + img.at<float>(y - 1, x - 1)) *
                    cross_derivative_scale;
  const float trace = dxx + dyy;
  const float det = dxx * dyy - dxy * dxy;
  if (det <= 0 ||
      trace * trace * kEdgeThreshold >= (kEdgeThreshold + 1) * (kEdgeThreshold + 1) * det) {
    return false;
  }
  kpt->pt.x = (x + xc) * (1 << octave);
  kpt->pt.y = (y + xr) * (1 << octave);
  kpt->octave = octave + (*layer << 8) + (cvRound((xi + 0.5) * 255) << 16);
  kpt->size = kSigma * powf(2.f, (*layer + xi) / kLayers) * (1 << octave) * 2;
  kpt->response = std::abs(contrast);
  return true;
}

// Working memory of one task's orientation histograms.
struct OrientationScratch {
  std::vector<float> x, y, orientation, weight;
  float histogram[kOrientationBins + 4];
};

// The gradient orientations around a keypoint, weighted by magnitude and a Gaussian, in 36 bins
// smoothed; returns the largest bin.
__attribute__((target("avx2,fma"))) float orientationHistogram(const cv::Mat& img, cv::Point pt,
                                                               int radius, float sigma, float* hist,
                                                               OrientationScratch* s) {
  constexpr int n = kOrientationBins;
  const size_t window = static_cast<size_t>(radius * 2 + 1) * (radius * 2 + 1);
  for (std::vector<float>* v : {&s->x, &s->y, &s->orientation, &s->weight}) {
    if (v->size() < window) v->resize(window);
  }
  float* X = s->x.data();
  float* Y = s->y.data();
  float* Ori = s->orientation.data();
  float* W = s->weight.data();
  float* Mag = X;
  float* temphist = s->histogram + 2;
  for (int i = 0; i < n; ++i) temphist[i] = 0.f;

  const float expf_scale = -1.f / (2.f * sigma * sigma);
  int len = 0;
  for (int i = -radius; i <= radius; ++i) {
    const int y = pt.y + i;
    if (y <= 0 || y >= img.rows - 1) continue;
    for (int j = -radius; j <= radius; ++j) {
      const int x = pt.x + j;
      if (x <= 0 || x >= img.cols - 1) continue;
      X[len] = img.at<float>(y, x + 1) - img.at<float>(y, x - 1);
      Y[len] = img.at<float>(y - 1, x) - img.at<float>(y + 1, x);
      W[len] = (i * i + j * j) * expf_scale;
      ++len;
    }
  }
  cv::hal::exp32f(W, W, len);
  cv::hal::fastAtan2(Y, X, Ori, len, true);
  cv::hal::magnitude32f(X, Y, Mag, len);

  // Eight at a time as OpenCV's AVX2 build: the bin by rounding, the weight times the magnitude
  // rounded before it is added.
  int k = 0;
  const __m256 per_degree = _mm256_set1_ps(n / 360.f);
  alignas(32) int bins[8];
  alignas(32) float terms[8];
  for (; k <= len - 8; k += 8) {
    const __m256i bin = _mm256_cvtps_epi32(_mm256_mul_ps(per_degree, _mm256_loadu_ps(Ori + k)));
    _mm256_store_si256(reinterpret_cast<__m256i*>(bins), bin);
    _mm256_store_ps(terms, _mm256_mul_ps(_mm256_loadu_ps(W + k), _mm256_loadu_ps(Mag + k)));
    for (int lane = 0; lane < 8; ++lane) {
      int b = bins[lane];
      if (b >= n) b -= n;
      if (b < 0) b += n;
      temphist[b] += terms[lane];
    }
  }
  for (; k < len; ++k) {
    int bin = cvRound((n / 360.f) * Ori[k]);
    if (bin >= n) bin -= n;
    if (bin < 0) bin += n;
    temphist[bin] += W[k] * Mag[k];
  }

  // Smoothed over five bins, eight at a time where OpenCV's AVX2 build does (a fused vector
  // multiply-add), the last four as its scalar code.
  temphist[-1] = temphist[n - 1];
  temphist[-2] = temphist[n - 2];
  temphist[n] = temphist[0];
  temphist[n + 1] = temphist[1];
  int i = 0;
  const __m256 d_1_16 = _mm256_set1_ps(1.f / 16.f);
  const __m256 d_4_16 = _mm256_set1_ps(4.f / 16.f);
  const __m256 d_6_16 = _mm256_set1_ps(6.f / 16.f);
  for (; i <= n - 8; i += 8) {
    const __m256 tn2 = _mm256_loadu_ps(temphist + i - 2);
    const __m256 tn1 = _mm256_loadu_ps(temphist + i - 1);
    const __m256 t0 = _mm256_loadu_ps(temphist + i);
    const __m256 t1 = _mm256_loadu_ps(temphist + i + 1);
    const __m256 t2 = _mm256_loadu_ps(temphist + i + 2);
    const __m256 smoothed =
        _mm256_fmadd_ps(_mm256_add_ps(tn2, t2), d_1_16,
                        _mm256_fmadd_ps(_mm256_add_ps(tn1, t1), d_4_16, _mm256_mul_ps(t0, d_6_16)));
    _mm256_storeu_ps(hist + i, smoothed);
  }
  for (; i < n; ++i) {
    hist[i] = (temphist[i - 2] + temphist[i + 2]) * (1.f / 16.f) +
              (temphist[i - 1] + temphist[i + 1]) * (4.f / 16.f) + temphist[i] * (6.f / 16.f);
  }
  float largest = hist[0];
  for (i = 1; i < n; ++i) largest = std::max(largest, hist[i]);
  return largest;
}

// The keypoint, once for each orientation peak within 80 % of the largest (its angle by a
// parabola through the peak and its neighbours).
__attribute__((target("avx2,fma"))) void addOrientedKeypoints(const SiftScaleSpace& space,
                                                              cv::KeyPoint kpt, int octave,
                                                              int layer, int r, int c,
                                                              OrientationScratch* scratch,
                                                              std::vector<cv::KeyPoint>* out) {
  constexpr int n = kOrientationBins;
  float hist[n];
  const float octave_scale = kpt.size * 0.5f / (1 << octave);
  const float largest =
      orientationHistogram(space.images[octave * kSiftLayersPerOctave + layer], cv::Point(c, r),
                           cvRound(kOrientationRadius * octave_scale),
                           kOrientationSigmaFactor * octave_scale, hist, scratch);
  const float threshold = static_cast<float>(largest * kOrientationPeakRatio);
  for (int j = 0; j < n; ++j) {
    const int left = j > 0 ? j - 1 : n - 1;
    const int right = j < n - 1 ? j + 1 : 0;
    if (hist[j] > hist[left] && hist[j] > hist[right] && hist[j] >= threshold) {
      float bin = j + 0.5f * (hist[left] - hist[right]) / (hist[left] - 2 * hist[j] + hist[right]);
      bin = bin < 0 ? n + bin : bin >= n ? bin - n : bin;
      kpt.angle = 360.f - static_cast<float>((360.f / n) * bin);
      if (std::abs(kpt.angle - 360.f) < FLT_EPSILON) kpt.angle = 0.f;
      out->push_back(kpt);
    }
  }
}

// The columns of [first, end) of a row whose value is an extremum (isExtremum), eight at a time:
// a value at least every neighbour's is at least their largest. Appends them to `columns`.
__attribute__((target("avx2,fma"))) void extremaInRow(const float* previous, const float* current,
                                                      const float* next, int first, int end,
                                                      int step, float threshold,
                                                      std::vector<int>* columns) {
  const __m256 sign = _mm256_set1_ps(-0.f);
  const __m256 limit = _mm256_set1_ps(threshold);
  const __m256 zero = _mm256_setzero_ps();
  int c = first;
  for (; c + 8 <= end; c += 8) {
    const __m256 value = _mm256_loadu_ps(current + c);
    // The 26 neighbours: the row's own two, and three in each of the 8 rows around.
    const float* neighbours[26] = {current + c - 1, current + c + 1};
    int n = 2;
    for (const float* row : {previous, next}) {
      for (int dc = -1; dc <= 1; ++dc) neighbours[n++] = row + c + dc;
    }
    for (const float* row : {previous, current, next}) {
      for (int offset : {-step, step}) {
        for (int dc = -1; dc <= 1; ++dc) neighbours[n++] = row + offset + c + dc;
      }
    }
    __m256 largest = _mm256_loadu_ps(neighbours[0]);
    __m256 smallest = largest;
    for (int k = 1; k < 26; ++k) {
      const __m256 v = _mm256_loadu_ps(neighbours[k]);
      largest = _mm256_max_ps(largest, v);
      smallest = _mm256_min_ps(smallest, v);
    }
    const __m256 strong = _mm256_cmp_ps(_mm256_andnot_ps(sign, value), limit, _CMP_GT_OQ);
    const __m256 maximum = _mm256_and_ps(_mm256_cmp_ps(value, zero, _CMP_GT_OQ),
                                         _mm256_cmp_ps(value, largest, _CMP_GE_OQ));
    const __m256 minimum = _mm256_and_ps(_mm256_cmp_ps(value, zero, _CMP_LT_OQ),
                                         _mm256_cmp_ps(value, smallest, _CMP_LE_OQ));
    int mask = _mm256_movemask_ps(_mm256_and_ps(strong, _mm256_or_ps(maximum, minimum)));
    while (mask != 0) {
      columns->push_back(c + __builtin_ctz(mask));
      mask &= mask - 1;
    }
  }
  for (; c < end; ++c) {
    if (isExtremum(previous, current, next, c, step, threshold)) columns->push_back(c);
  }
}

// One band of rows of one difference image: its extrema, refined and oriented.
void findInRows(const SiftScaleSpace& space, const std::vector<cv::Mat>& dog, int octave, int layer,
                int first_row, int end_row, float threshold, float contrast_threshold,
                std::vector<cv::KeyPoint>* out) {
  const int index = octave * kDogPerOctave + layer;
  const cv::Mat& img = dog[index];
  const int step = static_cast<int>(img.step1());
  OrientationScratch scratch;
  std::vector<int> columns;
  for (int r = first_row; r < end_row; ++r) {
    columns.clear();
    extremaInRow(dog[index - 1].ptr<float>(r), img.ptr<float>(r), dog[index + 1].ptr<float>(r),
                 kBorder, img.cols - kBorder, step, threshold, &columns);
    for (int c : columns) {
      cv::KeyPoint kpt;
      int r1 = r, c1 = c, refined_layer = layer;
      if (!refineExtremum(dog, &kpt, octave, &refined_layer, &r1, &c1, contrast_threshold)) {
        continue;
      }
      addOrientedKeypoints(space, kpt, octave, refined_layer, r1, c1, &scratch, out);
    }
  }
}

}  // namespace

bool siftDetectionAvailable() {
  return fastSiftDescriptorsAvailable() && !cv::checkHardwareSupport(CV_CPU_AVX512_SKX);
}

SiftScaleSpace siftDetectionScaleSpace(const cv::Mat& image) {
  if (image.empty() || image.depth() != CV_8U ||
      (image.channels() != 1 && image.channels() != 3 && image.channels() != 4)) {
    throw Error("SIFT detection needs an 8-bit grey or colour image");
  }
  // An image too small for one octave gets none, and no keypoints, as in OpenCV.
  const int octaves = std::max(0, siftOctaveCount(image.size()));
  return siftScaleSpace(image, octaves - 2, kSiftLayersPerOctave - 1);
}

std::vector<cv::KeyPoint> siftKeypoints(const SiftScaleSpace& space, int features,
                                        double contrast_threshold) {
  if (!siftDetectionAvailable()) throw Error("SIFT detection here needs AVX2 and FMA, not AVX-512");
  const std::vector<cv::Mat> dog = differenceOfGaussians(space);
  // OpenCV's pixel threshold: half the contrast threshold over the layers, in grey levels,
  // rounded down to a whole number.
  const float threshold = static_cast<float>(cvFloor(0.5 * contrast_threshold / kLayers * 255));
  // Bands of rows of every layer, each with its own list: the order the lists are joined in does
  // not matter, as OpenCV sorts them (removeDuplicatedSorted) before anything reads the order.
  struct Band {
    int octave, layer, first_row, end_row;
  };
  std::vector<Band> bands;
  for (int o = 0; o < space.octaves; ++o) {
    for (int i = 1; i <= kLayers; ++i) {
      const int rows = dog[o * kDogPerOctave + i].rows;
      for (int r = kBorder; r < rows - kBorder; r += kRowsATask) {
        bands.push_back({o, i, r, std::min(rows - kBorder, r + kRowsATask)});
      }
    }
  }
  std::vector<std::vector<cv::KeyPoint>> found(bands.size());
  tbb::parallel_for(0, static_cast<int>(bands.size()), [&](int b) {
    const Band& band = bands[b];
    findInRows(space, dog, band.octave, band.layer, band.first_row, band.end_row, threshold,
               static_cast<float>(contrast_threshold), &found[b]);
  });
  std::vector<cv::KeyPoint> keypoints;
  for (const auto& list : found) keypoints.insert(keypoints.end(), list.begin(), list.end());
  cv::KeyPointsFilter::removeDuplicatedSorted(keypoints);
  if (features > 0) cv::KeyPointsFilter::retainBest(keypoints, features);
  // Back from the doubled image (octave -1) to the image's own pixels.
  for (cv::KeyPoint& kpt : keypoints) {
    kpt.octave = (kpt.octave & ~255) | ((kpt.octave - 1) & 255);
    kpt.pt *= 0.5f;
    kpt.size *= 0.5f;
  }
  return keypoints;
}

void siftDetectAndCompute(const cv::Mat& image, int features, double contrast_threshold,
                          std::vector<cv::KeyPoint>* keypoints, cv::Mat* descriptors) {
  const SiftScaleSpace space = siftDetectionScaleSpace(image);
  *keypoints = siftKeypoints(space, features, contrast_threshold);
  *descriptors = siftDescriptors(space, *keypoints);
}

}  // namespace pnpba
