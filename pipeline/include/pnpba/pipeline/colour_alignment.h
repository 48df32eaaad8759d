// Coloured alignment of two RGB-D frames from a seed pose: both depth images back-projected
// with their colours, then Open3D's coloured ICP (Park, Zhou, Koltun, ICCV 2017: point-to-plane
// geometry plus the colour gradient of the target's surface) from a coarse voxel to a fine
// one. Colour fixes what depth alone leaves sliding (a cabinet's planes, a floor and a wall);
// depth keeps the colour term from drifting in uniform regions. Open3D stays behind the .cpp.
//
// T_21 maps camera-1 points onto camera-2 points (DESIGN.md section 3). Deterministic.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "pnpba/features/pinhole_camera.h"
#include "pnpba/optimize/se3_quat.h"

namespace pnpba {

struct ColourAlignmentOptions {
  // Voxel sizes, coarse to fine; each level's correspondence distance is 1.5 voxels, its
  // normals use 2 voxels. The coarse level widens the basin, the fine one sets accuracy.
  std::vector<double> voxels_m{0.08, 0.04, 0.02};
  int iterations = 30;             // per level
  double lambda_geometric = 0.968;  // Open3D's weight of the geometric term (colour: 1 - this)
  int pixel_stride = 2;             // back-project every n-th pixel before down-sampling
  double max_range_m = 6.0;
  std::string validate() const;  // empty when valid
};

struct ColourAlignment {
  bool ok = false;
  std::string failure;
  SE3Quat T_21;
  double fitness = 0;      // fraction of fine cloud-1 points with a cloud-2 point in reach
  double inlier_rmse = 0;  // m
  double time_ms = 0;
};

// image1/image2: 8-bit grey or BGR of the depths' size. Throws Error for invalid options or
// depths that are not CV_16UC1; ok = false when there is too little depth.
ColourAlignment alignColouredDepths(const cv::Mat& image1, const cv::Mat& depth1,
                                    const cv::Mat& image2, const cv::Mat& depth2,
                                    const PinholeCamera& camera, double depth_scale,
                                    const SE3Quat& T_seed, const ColourAlignmentOptions& options);

}  // namespace pnpba
