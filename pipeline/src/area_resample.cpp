#include "area_resample.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "pnpba/core/error.h"

namespace pnpba {

namespace {

// One output sample's share of an input index.
struct Tap {
  int index;
  float weight;
};

// Output sample k covers input [k r, (k + 1) r), r = in / out; each input pixel inside it weighs
// by the length it shares with that interval, over r. taps[first[k] .. first[k + 1]).
struct Taps {
  std::vector<Tap> taps;
  std::vector<int> first;
};

Taps areaTaps(int in, int out) {
  Taps t;
  const double r = static_cast<double>(in) / out;
  t.first.reserve(out + 1);
  for (int k = 0; k < out; ++k) {
    t.first.push_back(static_cast<int>(t.taps.size()));
    const double begin = k * r, end = std::min<double>((k + 1) * r, in);
    for (int i = static_cast<int>(std::floor(begin)); i < end; ++i) {
      const double shared = std::min<double>(i + 1, end) - std::max<double>(i, begin);
      if (shared > 1e-9) t.taps.push_back({i, static_cast<float>(shared / r)});
    }
  }
  t.first.push_back(static_cast<int>(t.taps.size()));
  return t;
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
  std::vector<float> row(image.cols);
  cv::Mat out(size, CV_32FC1);
  for (int y = 0; y < size.height; ++y) {
    std::fill(row.begin(), row.end(), 0.0f);
    for (int k = down.first[y]; k < down.first[y + 1]; ++k) {
      const float* in = image.ptr<float>(down.taps[k].index);
      const float w = down.taps[k].weight;
      for (int u = 0; u < image.cols; ++u) row[u] += w * in[u];
    }
    float* o = out.ptr<float>(y);
    for (int x = 0; x < size.width; ++x) {
      float sum = 0;
      for (int k = across.first[x]; k < across.first[x + 1]; ++k) {
        sum += across.taps[k].weight * row[across.taps[k].index];
      }
      o[x] = sum;
    }
  }
  return out;
}

}  // namespace pnpba
