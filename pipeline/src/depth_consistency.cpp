#include "pnpba/pipeline/depth_consistency.h"

#include <oneapi/tbb/parallel_invoke.h>

#include <cmath>
#include <vector>

#include "nearest_pixel.h"

namespace pnpba {

namespace {

void oneDirection(const cv::Mat& from, const cv::Mat& to, const SE3Quat& T, const PinholeCamera& k,
                  double scale, int stride, double noise_k, DepthConsistency* out) {
  // A row in two passes: first where each sample lands in `to`, then what `to` holds there. The
  // reads of `to` land all over an image larger than the cache; one after the other, each waited
  // for its miss, where a row's worth of independent reads overlap their misses.
  const int first = stride / 2;
  const int samples_per_row = (from.cols - first + stride - 1) / stride;
  // k.backProject's (u - cx) / fx once per sampled column, (v - cy) / fy once per sampled row:
  // at every 32nd pixel, a table of every column and row had been a fifth of a call.
  std::vector<double> x_of(samples_per_row);
  for (int j = 0; j < samples_per_row; ++j) x_of[j] = (first + j * stride - k.cx) / k.fx;
  // The depth path measures dozens of poses a pair: a rotation matrix and reciprocals, not the
  // quaternion and four divisions a sample (the counts, not the bits, are the result).
  const Eigen::Matrix3d R = T.rotation().toRotationMatrix();
  const Eigen::Vector3d t = T.translation();
  const double per_unit = 1.0 / scale;
  std::vector<const uint16_t*> seen_at(samples_per_row);
  std::vector<double> z_moved(samples_per_row);
  for (int v = first; v < from.rows; v += stride) {
    const uint16_t* row = from.ptr<uint16_t>(v);
    const double y_of_v = (v - k.cy) / k.fy;
    int landed = 0;
    for (int j = 0, u = first; j < samples_per_row; ++j, u += stride) {
      const uint16_t raw = row[u];
      if (raw == 0) continue;
      const double z = raw * per_unit;
      const Eigen::Vector3d X = R * Eigen::Vector3d(x_of[j] * z, y_of_v * z, z) + t;
      if (X.z() < 0.1) continue;
      const double iz = 1.0 / X.z();
      const int x = nearestPixel(k.fx * X.x() * iz + k.cx);
      const int y = nearestPixel(k.fy * X.y() * iz + k.cy);
      if (x < 0 || y < 0 || x >= to.cols || y >= to.rows) continue;
      seen_at[landed] = to.ptr<uint16_t>(y) + x;
      z_moved[landed] = X.z();
      ++landed;
    }
    for (int i = 0; i < landed; ++i) {
      const uint16_t seen = *seen_at[i];
      if (seen == 0) continue;
      ++out->checked;
      const double z_seen = seen * per_unit;
      const double tolerance = 0.02 + 2.0 * noise_k * z_seen * z_seen;
      const double gap = z_moved[i] - z_seen;  // < 0: in front of the seen surface
      if (std::abs(gap) <= tolerance) {
        ++out->agree;
      } else if (gap < -tolerance) {
        ++out->contradict;
      }
    }
  }
}

}  // namespace

DepthConsistency measureDepthConsistency(const cv::Mat& depth1, const cv::Mat& depth2,
                                         const SE3Quat& T_21, const PinholeCamera& camera,
                                         double depth_scale, int stride, double noise_k) {
  DepthConsistency c;
  if (depth1.empty() || depth2.empty()) return c;
  // The two directions on both cores (the depth path measures dozens of poses a pair: its slide
  // search and slide sigmas); their counts add up to the same whichever finishes first.
  DepthConsistency backward;
  tbb::parallel_invoke(
      [&] { oneDirection(depth1, depth2, T_21, camera, depth_scale, stride, noise_k, &c); },
      [&] {
        oneDirection(depth2, depth1, T_21.inverse(), camera, depth_scale, stride, noise_k,
                     &backward);
      });
  c.agree += backward.agree;
  c.contradict += backward.contradict;
  c.checked += backward.checked;
  return c;
}

}  // namespace pnpba
