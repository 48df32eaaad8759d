#include "depth_cloud.h"

#include <opencv2/calib3d.hpp>
#include <vector>

namespace pnpba {

std::shared_ptr<Cloud> depthCloud(const cv::Mat& depth, const PinholeCamera& camera,
                                  double depth_scale, int stride, double max_range_m) {
  std::vector<cv::Point2f> raw;
  std::vector<double> z;
  for (int v = 0; v < depth.rows; v += stride) {
    for (int u = 0; u < depth.cols; u += stride) {
      const uint16_t d = depth.at<uint16_t>(v, u);
      const double metres = d / depth_scale;
      if (d == 0 || metres < 0.1 || metres > max_range_m) continue;
      raw.emplace_back(static_cast<float>(u), static_cast<float>(v));
      z.push_back(metres);
    }
  }
  std::vector<cv::Point2f> normalised;
  if (camera.hasDistortion() && !raw.empty()) {
    const cv::Matx33d K(camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1);
    const cv::Mat dist(1, 5, CV_64F, const_cast<double*>(camera.distortion.data()));
    cv::undistortPoints(raw, normalised, K, dist);
  } else {
    for (const cv::Point2f& p : raw) {
      normalised.emplace_back(static_cast<float>((p.x - camera.cx) / camera.fx),
                              static_cast<float>((p.y - camera.cy) / camera.fy));
    }
  }
  auto cloud = std::make_shared<Cloud>();
  cloud->points.reserve(z.size());
  for (size_t i = 0; i < z.size(); ++i) {
    cloud->points.emplace_back(normalised[i].x * z[i], normalised[i].y * z[i], z[i]);
  }
  return cloud;
}

}  // namespace pnpba
