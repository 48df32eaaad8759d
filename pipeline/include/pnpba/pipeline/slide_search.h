// Where a depth-path pose may rest along a plain wall. The RGB-D alignment's point-to-plane and
// colour terms are flat along a plain surface: the few pixels that pin a slide (a cabinet's
// side faces, seen obliquely) land on other surfaces once the pose is a few centimetres off and
// leave its gates, so the alignment stays wherever its seed put it. The depth consistency
// (depth_consistency.h) still sees the slide: points land in front of surfaces the other camera
// sees, and its share grows with the offset. Measured on the rendered cabinet (Kinect-like
// depth, a calibration off by a checkerboard's error): poses 5-12 cm off along the wall at
// consistency 0.965-0.975, the truth 0.98, the consistency rising towards it along the line.
//
// The search steps the pose along camera 2's x, y and z axes (a left translation) and returns
// the shifted pose the depths support best when it beats the pose's own consistency by a
// margin: a seed to align again from, never an answer by itself. A slide that comes with a
// turn (the exact-calibration cabinet's 14-17 cm poses at 20-30 degrees) gains less than the
// margin along a pure translation and is not reached (docs/two_view.md, the depth path).
#pragma once

#include <Eigen/Core>
#include <functional>
#include <string>

#include "pnpba/optimize/se3_quat.h"

namespace pnpba {

struct SlideSearchOptions {
  double step_m = 0.04;     // the shift per step (0: no search)
  int steps = 5;            // steps each way along each axis: up to steps * step_m
  double min_gain = 0.005;  // consistency a shift must gain: about 3 sigma of its sampling noise
  std::string validate() const;  // empty when valid
};

struct SlideSeed {
  bool found = false;
  SE3Quat T;                // the shifted pose (found) or the pose itself
  double consistency = -1;  // at T
  int evaluations = 0;      // consistency_at calls made
};

// consistency_at(T): the depth consistency of a pose; it is called from several threads at once
// (TBB, on the cores there are). Evaluates 6 * steps shifts.
SlideSeed findSlideSeed(const SE3Quat& T, double consistency,
                        const std::function<double(const SE3Quat&)>& consistency_at,
                        const SlideSearchOptions& options);

// How far the depths pin a pose along camera 2's x, y and z axes: the 1-sigma of a left
// translation along each, from the consistency `probe_m` away on either side. Near its peak the
// consistency falls as a parabola, drop = a s^2, and a drop below its sampling noise
// `consistency_sigma` does not tell the poses apart: sigma^2 = probe^2 * consistency_sigma /
// drop, with the smaller of the two sides' drops (a pose off its peak is as loose as its flatter
// side). A drop below a quarter of the noise counts as a quarter, so a flat profile gives
// 2 * probe_m: it says the pose is loose over the probe, not how far beyond (a pose the depths
// leave free altogether is the alignment information's to say). Six consistencies, on the cores
// there are (consistency_at as for findSlideSeed).
Eigen::Vector3d slideSigmas(const SE3Quat& T, double consistency,
                            const std::function<double(const SE3Quat&)>& consistency_at,
                            double probe_m, double consistency_sigma);

}  // namespace pnpba
