#include "pnpba/evaluation/opencv_baseline.h"

#include <chrono>
#include <opencv2/calib3d.hpp>
#include <opencv2/features2d.hpp>

namespace pnpba {

namespace {

SE3Quat fromRvecTvec(const cv::Mat& rvec, const cv::Mat& tvec) {
  cv::Matx33d R;
  cv::Rodrigues(rvec, R);
  Eigen::Matrix3d Re;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) Re(r, c) = R(r, c);
  return SE3Quat(Re, Eigen::Vector3d(tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2)));
}

}  // namespace

TwoViewResult estimateTwoViewOpenCv(const cv::Mat& image1, const cv::Mat& depth1,
                                    const cv::Mat& image2, const Camera& camera,
                                    const OpenCvBaselineOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  TwoViewResult r;
  auto finish = [&](const std::string& failure) {
    r.failure = failure;
    r.ok = failure.empty();
    r.times_ms.total_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return r;
  };
  cv::Ptr<cv::ORB> orb = cv::ORB::create(options.features);
  std::vector<cv::KeyPoint> k1, k2;
  cv::Mat d1, d2;
  orb->detectAndCompute(image1, cv::noArray(), k1, d1);
  orb->detectAndCompute(image2, cv::noArray(), k2, d2);
  r.counts.keypoints1 = static_cast<int>(k1.size());
  r.counts.keypoints2 = static_cast<int>(k2.size());
  if (k1.empty() || k2.empty()) return finish("no keypoints");
  std::vector<std::vector<cv::DMatch>> knn;
  cv::BFMatcher(cv::NORM_HAMMING).knnMatch(d1, d2, knn, 2);
  std::vector<cv::Point2f> raw1, raw2;
  for (const auto& m : knn) {
    if (m.size() == 2 && m[0].distance < options.ratio * m[1].distance) {
      raw1.push_back(k1[m[0].queryIdx].pt);
      raw2.push_back(k2[m[0].trainIdx].pt);
    }
  }
  r.counts.matches = static_cast<int>(raw1.size());
  if (raw1.empty()) return finish("no matches");
  const cv::Matx33d K(camera.pinhole.fx, 0, camera.pinhole.cx, 0, camera.pinhole.fy,
                      camera.pinhole.cy, 0, 0, 1);
  const cv::Mat dist(1, 5, CV_64F, const_cast<double*>(camera.pinhole.distortion.data()));
  std::vector<cv::Point2f> und1, und2;
  cv::undistortPoints(raw1, und1, K, dist, cv::noArray(), K);
  cv::undistortPoints(raw2, und2, K, dist, cv::noArray(), K);
  std::vector<cv::Point3f> object;
  std::vector<cv::Point2f> image;
  for (size_t i = 0; i < raw1.size(); ++i) {
    const int x = static_cast<int>(raw1[i].x), y = static_cast<int>(raw1[i].y);
    const uint16_t d = depth1.at<uint16_t>(y, x);
    if (d == 0) continue;
    const float z = static_cast<float>(d / camera.depth_scale);
    object.emplace_back((und1[i].x - camera.pinhole.cx) / camera.pinhole.fx * z,
                        (und1[i].y - camera.pinhole.cy) / camera.pinhole.fy * z, z);
    image.push_back(und2[i]);
  }
  r.counts.pairs = static_cast<int>(object.size());
  if (object.size() < 6) return finish(std::to_string(object.size()) + " pairs < 6 required");
  cv::Mat rvec, tvec;
  std::vector<int> inliers;
  if (!cv::solvePnPRansac(object, image, K, cv::noArray(), rvec, tvec, false, options.iterations,
                          static_cast<float>(options.threshold_px), options.confidence, inliers,
                          cv::SOLVEPNP_EPNP) ||
      inliers.size() < 6) {
    return finish(std::to_string(inliers.size()) + " RANSAC inliers < 6 required");
  }
  r.counts.inliers = static_cast<int>(inliers.size());
  r.T_init = fromRvecTvec(rvec, tvec);
  std::vector<cv::Point3f> obj_in;
  std::vector<cv::Point2f> img_in;
  for (int i : inliers) {
    obj_in.push_back(object[i]);
    img_in.push_back(image[i]);
  }
  cv::solvePnPRefineLM(obj_in, img_in, K, cv::noArray(), rvec, tvec);
  r.T_21 = fromRvecTvec(rvec, tvec);
  r.solver = "opencv";
  return finish("");
}

}  // namespace pnpba
