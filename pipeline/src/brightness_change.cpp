#include "brightness_change.h"

#include <cmath>

namespace pnpba {

namespace {

// |residual| of every sample into *out, returning its robust scale.
double robustScale(const std::vector<const std::vector<DenseResidual>*>& spans,
                   const BrightnessChange& change, double floor, std::vector<double>* out) {
  out->clear();
  for (const std::vector<DenseResidual>* span : spans) {
    for (const DenseResidual& r : *span) out->push_back(std::abs(change.residual(r)));
  }
  return robustSigmaOf(out, floor);
}

}  // namespace

BrightnessChange fitBrightnessChange(const std::vector<const std::vector<DenseResidual>*>& spans,
                                     double gain_sigma, double huber_sigmas, double sigma_floor,
                                     std::vector<double>* scratch) {
  BrightnessChange change;
  scratch->clear();
  for (const std::vector<DenseResidual>* span : spans) {
    for (const DenseResidual& r : *span) scratch->push_back(r.value);
  }
  change.offset = medianInPlace(scratch);
  change.sigma = robustScale(spans, change, sigma_floor, scratch);
  if (!(gain_sigma > 0)) return change;
  for (int pass = 0; pass < 3; ++pass) {
    // Weighted least squares of value = gain i1 + offset: the 2 x 2 normal equations, the prior
    // adding (sigma / gain_sigma)^2 to the gain's diagonal (both sides in intensity units^2).
    double sw = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (const std::vector<DenseResidual>* span : spans) {
      for (const DenseResidual& r : *span) {
        const double e = std::abs(change.residual(r)) / change.sigma;
        const double w = e <= huber_sigmas ? 1.0 : huber_sigmas / e;
        sw += w;
        sx += w * r.i1;
        sy += w * r.value;
        sxx += w * r.i1 * r.i1;
        sxy += w * r.i1 * r.value;
      }
    }
    const double prior = (change.sigma / gain_sigma) * (change.sigma / gain_sigma);
    const double det = (sxx + prior) * sw - sx * sx;
    if (!(sw > 0) || !(det > 0)) break;
    change.gain = (sw * sxy - sx * sy) / det;
    change.offset = (sy - change.gain * sx) / sw;
    change.sigma = robustScale(spans, change, sigma_floor, scratch);
  }
  return change;
}

}  // namespace pnpba
