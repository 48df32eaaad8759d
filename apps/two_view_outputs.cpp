#include "two_view_outputs.h"

#include <opencv2/imgcodecs.hpp>  // the flags; the codecs come through pnpba::imageio
#include <opencv2/imgproc.hpp>

#include "pnpba/core/error.h"
#include "pnpba/core/output_file.h"
#include "pnpba/imageio/image_codec.h"
#include "pnpba/pipeline/two_view_report.h"

namespace pnpba {

void writeTwoViewJson(const std::string& path, const TwoViewResult& r, const std::string& ba_mode) {
  const std::string text = twoViewReportJson(r, ba_mode);
  writeOutputFile(path, [&text](std::ostream& out) { out << text; });
}

void writeMatchesPng(const std::string& path, const cv::Mat& image1, const cv::Mat& image2,
                     const TwoViewResult& r) {
  auto colour = [](const cv::Mat& m) {
    cv::Mat c;
    if (m.channels() == 1) {
      cv::cvtColor(m, c, cv::COLOR_GRAY2BGR);
    } else {
      c = m.clone();
    }
    return c;
  };
  const cv::Mat a = colour(image1), b = colour(image2);
  cv::Mat canvas(a.rows + b.rows, std::max(a.cols, b.cols), CV_8UC3, cv::Scalar::all(0));
  a.copyTo(canvas(cv::Rect(0, 0, a.cols, a.rows)));
  b.copyTo(canvas(cv::Rect(0, a.rows, b.cols, b.rows)));
  for (size_t i = 0; i < r.pairs.size(); ++i) {
    const cv::Point2f p1 = r.keypoints1[r.pairs[i].keypoint_1].pt;
    const cv::Point2f p2 = r.keypoints2[r.pairs[i].keypoint_2].pt + cv::Point2f(0, a.rows);
    const bool inlier = i < r.inlier.size() && r.inlier[i];
    const cv::Scalar c = inlier ? cv::Scalar(0, 200, 0) : cv::Scalar(0, 0, 255);
    cv::line(canvas, p1, p2, c, 1, cv::LINE_AA);
    cv::circle(canvas, p1, 3, c, 1, cv::LINE_AA);
    cv::circle(canvas, p2, 3, c, 1, cv::LINE_AA);
  }
  std::vector<uchar> png;
  if (!pnpba::encodeImage(".png", canvas, &png)) throw Error(path + ": PNG encoding failed");
  writeOutputFile(path, [&png](std::ostream& out) {
    out.write(reinterpret_cast<const char*>(png.data()), static_cast<std::streamsize>(png.size()));
  });
}

void writeTwoViewPly(const std::string& path, const TwoViewResult& r) {
  std::vector<Eigen::Vector3d> points;
  for (size_t i = 0; i < r.pairs.size(); ++i) {
    if (i < r.inlier.size() && r.inlier[i]) points.push_back(r.pairs[i].X_1);
  }
  const Eigen::Vector3d centre2 = r.T_21.inverse().translation();  // -R^T t
  writeOutputFile(path, [&](std::ostream& out) {
    out << "ply\nformat ascii 1.0\ncomment pnpba two-view: camera-1 frame, metres\n"
        << "element vertex " << points.size() + 2 << "\n"
        << "property float x\nproperty float y\nproperty float z\n"
        << "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n";
    for (const Eigen::Vector3d& p : points) {
      out << p.x() << " " << p.y() << " " << p.z() << " 255 255 255\n";
    }
    out << "0 0 0 0 255 0\n";
    out << centre2.x() << " " << centre2.y() << " " << centre2.z() << " 0 255 0\n";
  });
}

}  // namespace pnpba
