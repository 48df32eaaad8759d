// What a consumer RGB-D sensor and its recording do to a rendered view beyond Gaussian depth
// noise (synthetic_scene.h): the structured-light depth's disparity steps, holes along depth
// edges, a colour image not quite registered with the depth, and lossy JPEG colour. The
// real texture-poor failures (TUM fr3_cabinet) come with all four; the renderer's clean views
// do not reproduce them.
#pragma once

#include <string>

#include "pnpba/synthetic/synthetic_scene.h"

namespace pnpba {

struct SensorEffects {
  // Depth from disparity d = f b / z stored in 1/subpixel steps (Kinect: f b = 580 px x 7.5 cm,
  // 1/8 px): steps of z^2 / (f b subpixel), 1.1 cm at 2 m. 0 = off.
  double disparity_fb = 0;  // px m
  int disparity_subpixel = 8;
  int edge_hole_px = 0;  // depth dropped within this many pixels of a depth jump (> 5 % of z)
  // The depth image shifted against the colour image by this many pixels (registration error).
  int depth_offset_px_x = 0, depth_offset_px_y = 0;
  int jpeg_quality = 0;  // colour re-encoded as JPEG at this quality (1-100); 0 = off

  // Kinect-like: all of the above at typical strengths.
  static SensorEffects kinectLike();
  std::string validate() const;  // empty when valid
};

// Applies the effects to a view in place (depth_scale: depth value per metre).
void applySensorEffects(const SensorEffects& effects, double depth_scale, RenderedView* view);

}  // namespace pnpba
