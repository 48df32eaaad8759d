// predictedRegistrationKilopoints (registration_work.h) against areas and voxels worked out by
// hand on walls facing the camera.
#include "registration_work.h"

#include <gtest/gtest.h>

namespace pnpba {
namespace {

constexpr double kScale = 5000;  // depth units per metre

PinholeCamera camera() {
  PinholeCamera c;
  c.fx = 500, c.fy = 520, c.cx = 319.5, c.cy = 239.5;
  return c;
}

cv::Mat wall(double z) { return cv::Mat(480, 640, CV_16U, cv::Scalar(z * kScale)); }

// The points a wall at depth z facing the camera keeps on the voxel grid: its area over the
// voxel's face, the whole 640 x 480 image seeing it.
double wallPoints(double z, double voxel) {
  const double width = 640 * z / 500, height = 480 * z / 520;
  return width * height / (voxel * voxel);
}

TEST(RegistrationWork, AWallIsItsAreaOverTheVoxelsFace) {
  DepthRegistrationOptions o;
  o.max_points = 0;
  // At 4 m the voxel is the ceiling (0.05 x 4 m > 10 cm).
  EXPECT_NEAR(predictedRegistrationKilopoints(wall(4), wall(4), camera(), kScale, o),
              2 * wallPoints(4, o.voxel_m) / 1000, 1e-9);
  // Nearer, the voxel is a fraction of depth 1's median: a wall at 1 m and at 1.5 m keep as many
  // points (area and voxel face both grow as z^2).
  const double at1 = predictedRegistrationKilopoints(wall(1), wall(1), camera(), kScale, o);
  EXPECT_NEAR(at1, 2 * wallPoints(1, 0.05) / 1000, 1e-9);
  EXPECT_NEAR(predictedRegistrationKilopoints(wall(1.5), wall(1.5), camera(), kScale, o), at1,
              1e-9);
  // Depth 2's wall twice as far keeps four times the points on depth 1's voxel.
  EXPECT_NEAR(predictedRegistrationKilopoints(wall(1), wall(2), camera(), kScale, o),
              5 * wallPoints(1, 0.05) / 1000, 1e-9);
}

TEST(RegistrationWork, HolesAndFarDepthsCountForNothing) {
  DepthRegistrationOptions o;
  o.max_points = 0;
  const double full = predictedRegistrationKilopoints(wall(4), wall(4), camera(), kScale, o);
  cv::Mat half = wall(4);
  half.rowRange(0, 240).setTo(0);  // holes
  EXPECT_NEAR(predictedRegistrationKilopoints(wall(4), half, camera(), kScale, o), 0.75 * full,
              1e-9);
  half.rowRange(0, 240).setTo(o.max_range_m * kScale + 100);  // beyond the registration's range
  EXPECT_NEAR(predictedRegistrationKilopoints(wall(4), half, camera(), kScale, o), 0.75 * full,
              1e-9);
  EXPECT_EQ(predictedRegistrationKilopoints(cv::Mat::zeros(480, 640, CV_16U), wall(4), camera(),
                                            kScale, o),
            0.0);
}

TEST(RegistrationWork, PastMaxPointsBothCloudsShrinkAsTheVoxelGrows) {
  DepthRegistrationOptions o;
  const double points = wallPoints(4, o.voxel_m);
  o.max_points = static_cast<int>(points / 4);  // the voxel doubles: each cloud a quarter
  cv::Mat half = wall(4);
  half.rowRange(0, 240).setTo(0);
  EXPECT_NEAR(predictedRegistrationKilopoints(wall(4), half, camera(), kScale, o),
              1.5 * o.max_points / 1000, 1e-9);
}

}  // namespace
}  // namespace pnpba
