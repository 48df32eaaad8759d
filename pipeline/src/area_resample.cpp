#include "area_resample.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "pnpba/core/error.h"

namespace pnpba {

namespace {

// Output sample k covers input [k r, (k + 1) r), r = in / out; each input pixel inside it weighs
// by the length it shares with that interval, over r. Every sample gets `width` weights, for
// inputs first[k] .. first[k] + width - 1, the ones past its interval zero, so that the loops
// below have a fixed count (r <= 2 after the view's halvings: at most three).
struct Taps {
  int width = 0;
  std::vector<int> first;
  std::vector<float> weights;  // width per sample
};

Taps areaTaps(int in, int out) {
  Taps t;
  const double r = static_cast<double>(in) / out;
  t.width = static_cast<int>(std::ceil(r)) + 1;
  t.first.resize(out);
  t.weights.assign(static_cast<size_t>(out) * t.width, 0.0f);
  for (int k = 0; k < out; ++k) {
    const double begin = k * r, end = std::min<double>((k + 1) * r, in);
    t.first[k] = static_cast<int>(std::floor(begin));
    for (int i = t.first[k]; i < end; ++i) {
      const double shared = std::min<double>(i + 1, end) - std::max<double>(i, begin);
      if (shared > 0) t.weights[static_cast<size_t>(k) * t.width + (i - t.first[k])] = shared / r;
    }
  }
  return t;
}

// One output row's columns from `row` (padded with zeros past its end), W weights each.
template <int W>
void columns(const Taps& across, const float* row, float* out, int count) {
  const float* w = across.weights.data();
  for (int x = 0; x < count; ++x, w += W) {
    const float* in = row + across.first[x];
    float sum = w[0] * in[0];
    for (int j = 1; j < W; ++j) sum += w[j] * in[j];
    out[x] = sum;
  }
}

void columnsAnyWidth(const Taps& across, const float* row, float* out, int count) {
  const float* w = across.weights.data();
  for (int x = 0; x < count; ++x, w += across.width) {
    const float* in = row + across.first[x];
    float sum = 0;
    for (int j = 0; j < across.width; ++j) sum += w[j] * in[j];
    out[x] = sum;
  }
}

}  // namespace

cv::Mat resampleByArea(const cv::Mat& image, cv::Size size) {
  if (image.type() != CV_32FC1 || size.width < 1 || size.height < 1 || size.width > image.cols ||
      size.height > image.rows) {
    throw Error("resampleByArea: a CV_32FC1 image and a smaller, non-empty size");
  }
  const Taps across = areaTaps(image.cols, size.width);
  const Taps down = areaTaps(image.rows, size.height);
  // Rows first, over whole input rows (contiguous, so the compiler vectorises them); then each
  // output row's columns from that one row.
  std::vector<float> row(image.cols + across.width, 0.0f);
  cv::Mat out(size, CV_32FC1);
  for (int y = 0; y < size.height; ++y) {
    const float* weight = down.weights.data() + static_cast<size_t>(y) * down.width;
    const float* first = image.ptr<float>(down.first[y]);
    for (int u = 0; u < image.cols; ++u) row[u] = weight[0] * first[u];
    for (int j = 1; j < down.width && down.first[y] + j < image.rows; ++j) {
      if (weight[j] == 0) continue;
      const float* in = image.ptr<float>(down.first[y] + j);
      for (int u = 0; u < image.cols; ++u) row[u] += weight[j] * in[u];
    }
    float* o = out.ptr<float>(y);
    switch (across.width) {
      case 2:
        columns<2>(across, row.data(), o, size.width);
        break;
      case 3:
        columns<3>(across, row.data(), o, size.width);
        break;
      default:
        columnsAnyWidth(across, row.data(), o, size.width);
    }
  }
  return out;
}

}  // namespace pnpba
