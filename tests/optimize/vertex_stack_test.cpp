// A vertex's saved estimates form a stack (g2o's push / pop / discardTop), however deep: LM saves
// one level per trial, a caller may save more.
#include <gtest/gtest.h>

#include "pnpba/optimize/vertex_point_xyz.h"

namespace pnpba {
namespace {

TEST(VertexStack, PopRestoresEveryLevelInReverseOrder) {
  VertexPointXYZ v;
  const int depth = 4;
  for (int k = 0; k < depth; ++k) {
    v.setEstimate(Eigen::Vector3d::Constant(k));
    v.push();
  }
  v.setEstimate(Eigen::Vector3d::Constant(99));
  for (int k = depth - 1; k >= 0; --k) {
    v.pop();
    EXPECT_EQ(v.estimate(), Eigen::Vector3d::Constant(k)) << "level " << k;
  }
}

TEST(VertexStack, DiscardTopKeepsTheEstimateAndExposesTheLevelBelow) {
  VertexPointXYZ v;
  v.setEstimate(Eigen::Vector3d(1, 2, 3));
  v.push();
  v.setEstimate(Eigen::Vector3d(4, 5, 6));
  v.push();
  v.setEstimate(Eigen::Vector3d(7, 8, 9));
  v.discardTop();  // (4, 5, 6) dropped, the estimate stays
  EXPECT_EQ(v.estimate(), Eigen::Vector3d(7, 8, 9));
  v.pop();
  EXPECT_EQ(v.estimate(), Eigen::Vector3d(1, 2, 3));
  // Empty again: a new level starts from scratch.
  v.push();
  v.setEstimate(Eigen::Vector3d::Zero());
  v.pop();
  EXPECT_EQ(v.estimate(), Eigen::Vector3d(1, 2, 3));
}

}  // namespace
}  // namespace pnpba
