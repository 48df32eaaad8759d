#include "pnpba/features/correspondences.h"

#include <opencv2/calib3d.hpp>

namespace pnpba {

std::vector<Eigen::Vector2d> undistortKeypoints(const std::vector<cv::KeyPoint>& keypoints,
                                                const PinholeCamera& camera) {
  std::vector<Eigen::Vector2d> out;
  out.reserve(keypoints.size());
  if (!camera.hasDistortion() || keypoints.empty()) {
    for (const cv::KeyPoint& k : keypoints) out.emplace_back(k.pt.x, k.pt.y);
    return out;
  }
  std::vector<cv::Point2f> raw, undistorted;
  for (const cv::KeyPoint& k : keypoints) raw.push_back(k.pt);
  const cv::Matx33d K(camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1);
  const cv::Mat dist(1, 5, CV_64F, const_cast<double*>(camera.distortion.data()));
  // P = K: the result is in pixels of the undistorted image.
  cv::undistortPoints(raw, undistorted, K, dist, cv::noArray(), K);
  for (const cv::Point2f& p : undistorted) out.emplace_back(p.x, p.y);
  return out;
}

Correspondences buildCorrespondences(const Features& features1, const Features& features2,
                                     const std::vector<cv::DMatch>& matches, const cv::Mat& depth1,
                                     const PinholeCamera& camera, const DepthOptions& depth_options,
                                     bool undistort) {
  const PinholeCamera model = [&] {
    PinholeCamera c = camera;
    if (!undistort) c.distortion = {};
    return c;
  }();
  const std::vector<Eigen::Vector2d> uv1 = undistortKeypoints(features1.keypoints, model);
  const std::vector<Eigen::Vector2d> uv2 = undistortKeypoints(features2.keypoints, model);
  Correspondences out;
  out.reserve(matches.size());
  for (const cv::DMatch& m : matches) {
    const cv::Point2f& raw1 = features1.keypoints[m.queryIdx].pt;
    const std::optional<double> z = depthAt(depth1, raw1.x, raw1.y, depth_options);
    if (!z) continue;
    Correspondence c;
    c.uv_1 = uv1[m.queryIdx];
    c.uv_2 = uv2[m.trainIdx];
    c.depth = *z;
    c.X_1 = model.backProject(c.uv_1, *z);
    c.descriptor_distance = static_cast<int>(m.distance);
    c.keypoint_1 = m.queryIdx;
    c.keypoint_2 = m.trainIdx;
    out.push_back(c);
  }
  return out;
}

}  // namespace pnpba
