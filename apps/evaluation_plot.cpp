#include "evaluation_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgcodecs.hpp>  // the flags; the codecs come through pnpba::imageio
#include <opencv2/imgproc.hpp>

#include "pnpba/core/error.h"
#include "pnpba/core/output_file.h"
#include "pnpba/imageio/image_codec.h"

namespace pnpba {

namespace {

const cv::Scalar kColours[] = {{200, 80, 20},  {40, 160, 40},  {30, 30, 220},
                               {160, 40, 160}, {20, 160, 200}, {90, 90, 90}};
constexpr int kWidth = 1000, kPanelHeight = 300, kLeft = 70, kRight = 20, kTop = 40;

// One panel: x = pair index, y = error (clipped at y_max, shown at the top), failures as
// crosses at the top; dashed line at the success threshold.
void drawPanel(cv::Mat& img, int top, const std::string& title, double threshold,
               const std::vector<std::string>& methods, const std::vector<PlotPair>& pairs,
               bool rotation) {
  double y_max = threshold * 2;
  for (const PlotPair& p : pairs)
    for (const PairOutcome& o : p.errors)
      if (o.ok) y_max = std::max(y_max, rotation ? o.error.rot_deg : o.error.trans_cm);
  y_max = std::min(y_max, threshold * 5);
  const int h = kPanelHeight - 60, w = kWidth - kLeft - kRight;
  const cv::Rect box(kLeft, top + kTop, w, h);
  cv::rectangle(img, box, cv::Scalar::all(0));
  cv::putText(img, title, {kLeft, top + 25}, cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar::all(0), 1,
              cv::LINE_AA);
  auto y_of = [&](double v) {
    return box.y + h - static_cast<int>(std::min(v, y_max) / y_max * h);
  };
  for (int t = 0; t <= 4; ++t) {
    const double v = y_max * t / 4;
    char label[32];
    std::snprintf(label, sizeof label, "%.2f", v);
    cv::putText(img, label, {5, y_of(v) + 4}, cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar::all(60), 1,
                cv::LINE_AA);
    cv::line(img, {kLeft - 4, y_of(v)}, {kLeft, y_of(v)}, cv::Scalar::all(0));
  }
  for (int x = kLeft; x < kLeft + w; x += 12) {
    cv::line(img, {x, y_of(threshold)}, {x + 6, y_of(threshold)}, cv::Scalar::all(150));
  }
  const int n = std::max<int>(1, static_cast<int>(pairs.size()));
  auto x_of = [&](int idx) { return box.x + static_cast<int>((idx + 0.5) * w / n); };
  for (size_t m = 0; m < methods.size(); ++m) {
    const cv::Scalar c = kColours[m % 6];
    cv::Point previous(-1, -1);
    for (int idx = 0; idx < static_cast<int>(pairs.size()); ++idx) {
      const PairOutcome& o = pairs[idx].errors[m];
      if (!o.ok) {
        const cv::Point p(x_of(idx), box.y + 6);
        cv::drawMarker(img, p, c, cv::MARKER_TILTED_CROSS, 9, 2);
        previous = {-1, -1};
        continue;
      }
      const cv::Point p(x_of(idx), y_of(rotation ? o.error.rot_deg : o.error.trans_cm));
      if (previous.x >= 0) cv::line(img, previous, p, c, 1, cv::LINE_AA);
      cv::circle(img, p, 3, c, cv::FILLED, cv::LINE_AA);
      previous = p;
    }
  }
}

}  // namespace

void writeEvaluationPlot(const std::string& path, const std::vector<std::string>& methods,
                         const std::vector<PlotPair>& pairs) {
  cv::Mat img(2 * kPanelHeight + 60, kWidth, CV_8UC3, cv::Scalar::all(255));
  drawPanel(img, 0, "rotation error (deg) per pair (i, i+k); dashed: 1 deg; x: failed", 1.0,
            methods, pairs, true);
  drawPanel(img, kPanelHeight, "translation error (cm) per pair; dashed: 2 cm", 2.0, methods, pairs,
            false);
  int x = kLeft;
  for (size_t m = 0; m < methods.size(); ++m) {
    cv::circle(img, {x, 2 * kPanelHeight + 30}, 5, kColours[m % 6], cv::FILLED);
    cv::putText(img, methods[m], {x + 10, 2 * kPanelHeight + 35}, cv::FONT_HERSHEY_SIMPLEX, 0.5,
                cv::Scalar::all(0), 1, cv::LINE_AA);
    x += 40 + 10 * static_cast<int>(methods[m].size());
  }
  std::vector<uchar> png;
  if (!pnpba::encodeImage(".png", img, &png)) throw Error(path + ": PNG encoding failed");
  writeOutputFile(path, [&png](std::ostream& out) {
    out.write(reinterpret_cast<const char*>(png.data()), static_cast<std::streamsize>(png.size()));
  });
}

}  // namespace pnpba
