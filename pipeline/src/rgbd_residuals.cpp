#include "rgbd_residuals.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace pnpba {

namespace {

cv::Mat greyFloat(const cv::Mat& image) {
  cv::Mat grey, out;
  if (image.channels() == 3) {
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  } else {
    grey = image;
  }
  grey.convertTo(out, CV_32F);
  return out;
}

cv::Mat metres(const cv::Mat& depth, double depth_scale) {
  cv::Mat out;
  depth.convertTo(out, CV_32F, 1.0 / depth_scale);
  return out;
}

cv::Mat everySecondPixel(const cv::Mat& m) {
  cv::Mat out(m.rows / 2, m.cols / 2, m.type());
  for (int v = 0; v < out.rows; ++v) {
    for (int u = 0; u < out.cols; ++u) out.at<float>(v, u) = m.at<float>(2 * v, 2 * u);
  }
  return out;
}

void gradients(RgbdLevel* l) {
  cv::Sobel(l->grey2, l->gx2, CV_32F, 1, 0, 3, 1.0 / 8.0);
  cv::Sobel(l->grey2, l->gy2, CV_32F, 0, 1, 3, 1.0 / 8.0);
}

float bilinear(const cv::Mat& m, double u, double v) {
  const int x = static_cast<int>(u), y = static_cast<int>(v);
  const float a = static_cast<float>(u - x), b = static_cast<float>(v - y);
  const float* r0 = m.ptr<float>(y);
  const float* r1 = m.ptr<float>(y + 1);
  return (1 - b) * ((1 - a) * r0[x] + a * r0[x + 1]) + b * ((1 - a) * r1[x] + a * r1[x + 1]);
}

// d(exp(d) X)/dd at d = 0 for [w, v]: [-[X]x, I].
Eigen::Matrix<double, 3, 6> pointJacobian(const Eigen::Vector3d& X) {
  Eigen::Matrix<double, 3, 6> J;
  J << 0, X.z(), -X.y(), 1, 0, 0,  //
      -X.z(), 0, X.x(), 0, 1, 0,   //
      X.y(), -X.x(), 0, 0, 0, 1;
  return J;
}

// Depth 2's point and normal at every pixel (a zero normal where there is none). Rows are
// independent, so they are shared among the cores (8 ms of a pair's depth path on one core at
// 640x480); every pixel is computed as on one thread, so the result does not depend on it.
void surfaces(RgbdLevel* l) {
  const int s = l->normal_step;
  const cv::Mat& depth = l->depth2;
  l->points2.create(depth.size(), CV_32FC3);
  l->normals2 = cv::Mat::zeros(depth.size(), CV_32FC3);
  auto point = [&](int u, int v) {
    return l->camera.backProject(Eigen::Vector2d(u, v), depth.at<float>(v, u));
  };
#pragma omp parallel for schedule(static)
  for (int v = 0; v < depth.rows; ++v) {
    for (int u = 0; u < depth.cols; ++u) {
      const float z = depth.at<float>(v, u);
      const Eigen::Vector3d P = point(u, v);
      l->points2.at<cv::Vec3f>(v, u) = cv::Vec3f(P.x(), P.y(), P.z());
      if (!(z > 0) || u < s || v < s || u + s >= depth.cols || v + s >= depth.rows) continue;
      const float zl = depth.at<float>(v, u - s), zr = depth.at<float>(v, u + s);
      const float zu = depth.at<float>(v - s, u), zd = depth.at<float>(v + s, u);
      const float edge = 0.05f + 0.02f * z;
      bool ok = true;
      for (float q : {zl, zr, zu, zd}) ok = ok && q > 0 && std::abs(q - z) <= edge;
      if (!ok) continue;
      Eigen::Vector3d n =
          (point(u + s, v) - point(u - s, v)).cross(point(u, v + s) - point(u, v - s));
      const double norm = n.norm();
      if (!(norm > 0)) continue;
      n /= norm;
      if (n.dot(P) > 0) n = -n;
      l->normals2.at<cv::Vec3f>(v, u) = cv::Vec3f(n.x(), n.y(), n.z());
    }
  }
}

}  // namespace

std::vector<RgbdLevel> rgbdPyramid(const cv::Mat& image1, const cv::Mat& depth1,
                                   const cv::Mat& image2, const cv::Mat& depth2,
                                   const PinholeCamera& camera, double depth_scale, int levels) {
  std::vector<RgbdLevel> out(1);
  out[0].grey1 = greyFloat(image1);
  out[0].grey2 = greyFloat(image2);
  out[0].depth1 = metres(depth1, depth_scale);
  out[0].depth2 = metres(depth2, depth_scale);
  out[0].camera = camera;
  out[0].normal_step = 2;
  out[0].camera.distortion = {};
  gradients(&out[0]);
  surfaces(&out[0]);
  for (int i = 1; i < levels; ++i) {
    const RgbdLevel& up = out.back();
    if (up.grey1.cols < 40 || up.grey1.rows < 40) break;
    RgbdLevel l;
    cv::pyrDown(up.grey1, l.grey1, cv::Size(up.grey1.cols / 2, up.grey1.rows / 2));
    cv::pyrDown(up.grey2, l.grey2, cv::Size(up.grey2.cols / 2, up.grey2.rows / 2));
    l.depth1 = everySecondPixel(up.depth1);
    l.depth2 = everySecondPixel(up.depth2);
    l.camera = up.camera;
    // pyrDown's pixel u' and the depth's every second pixel sit on the finer pixel 2 u'.
    l.camera.fx /= 2, l.camera.fy /= 2, l.camera.cx /= 2, l.camera.cy /= 2;
    l.normal_step = 1;
    gradients(&l);
    surfaces(&l);
    out.push_back(std::move(l));
  }
  return out;
}

DenseResiduals denseResiduals(const RgbdLevel& l, const SE3Quat& T_21,
                              const DenseResidualOptions& o, bool keep_intensities) {
  DenseResiduals out;
  const size_t expected =
      static_cast<size_t>(l.depth1.rows / o.stride + 1) * (l.depth1.cols / o.stride + 1);
  out.geometric.reserve(expected);
  out.photometric.reserve(expected);
  const PinholeCamera& k = l.camera;
  const int margin = std::max(2, l.normal_step);
  const Eigen::Matrix3d R = T_21.rotation().toRotationMatrix();
  const Eigen::Vector3d t = T_21.translation();
  for (int v = o.stride / 2; v < l.depth1.rows; v += o.stride) {
    const float* depth_row = l.depth1.ptr<float>(v);
    for (int u = o.stride / 2; u < l.depth1.cols; u += o.stride) {
      const float z1 = depth_row[u];
      if (!(z1 > 0)) continue;
      ++out.depth1_samples;
      const Eigen::Vector3d X = R * k.backProject(Eigen::Vector2d(u, v), z1) + t;
      if (X.z() < 0.1) continue;
      const Eigen::Vector2d uv = k.project(X);
      if (!(uv.x() >= margin && uv.y() >= margin && uv.x() < l.depth2.cols - margin - 1 &&
            uv.y() < l.depth2.rows - margin - 1)) {
        continue;
      }
      const int x = static_cast<int>(std::lround(uv.x()));
      const int y = static_cast<int>(std::lround(uv.y()));
      const cv::Vec3f& normal = l.normals2.at<cv::Vec3f>(y, x);
      if (normal[0] == 0 && normal[1] == 0 && normal[2] == 0) continue;
      const cv::Vec3f& point = l.points2.at<cv::Vec3f>(y, x);
      const Eigen::Vector3d P(point[0], point[1], point[2]), n(normal[0], normal[1], normal[2]);
      const double kz2 = o.depth_noise_k * P.z() * P.z();
      if (std::abs(X.z() - P.z()) > o.visibility_tolerances * (0.02 + 2.0 * kz2)) continue;
      const double sigma = o.depth_noise_floor_m + kz2;
      out.geometric.push_back({n.dot(X - P) / sigma, n.transpose() * pointJacobian(X) / sigma});
      const Eigen::RowVector2d grad(bilinear(l.gx2, uv.x(), uv.y()),
                                    bilinear(l.gy2, uv.x(), uv.y()));
      const double i1 = l.grey1.at<float>(v, u), i2 = bilinear(l.grey2, uv.x(), uv.y());
      out.photometric.push_back({i2 - i1, grad * projectionJacobian(k, X)});
      if (keep_intensities) {
        out.intensity1.push_back(i1);
        out.intensity2.push_back(i2);
      }
    }
  }
  return out;
}

Eigen::Matrix<double, 2, 6> projectionJacobian(const PinholeCamera& k, const Eigen::Vector3d& X) {
  const double iz = 1.0 / X.z();
  Eigen::Matrix<double, 2, 3> dpi;
  dpi << k.fx * iz, 0, -k.fx * X.x() * iz * iz, 0, k.fy * iz, -k.fy * X.y() * iz * iz;
  return dpi * pointJacobian(X);
}

double robustSigma(const std::vector<DenseResidual>& residuals, double floor, double offset) {
  if (residuals.empty()) return floor;
  std::vector<double> a;
  a.reserve(residuals.size());
  for (const DenseResidual& r : residuals) a.push_back(std::abs(r.value - offset));
  auto mid = a.begin() + a.size() / 2;
  std::nth_element(a.begin(), mid, a.end());
  return std::max(1.4826 * *mid, floor);
}

}  // namespace pnpba
