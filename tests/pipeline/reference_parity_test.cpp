// Parity with g2o on the textbook pair's 75 correspondences (shared/data/reference): the
// numbers below are g2o's and OpenCV's, from shared/data/reference/README.md.
#include <gtest/gtest.h>

#include <cmath>

#include "pnpba/optimize/vertex_se3_expmap.h"
#include "pnpba/pipeline/pairs_file.h"
#include "pnpba/pipeline/pose_graph.h"
#include "reference_data.h"
#include "shared_data.h"

namespace pnpba {
namespace {

const SE3Quat kEpnp = test::referenceEpnpPose();
const SE3Quat kLeastSquares = test::referenceLeastSquaresPose();
const SE3Quat kG2oTextbook = test::referenceG2oTextbookPose();
const SE3Quat kG2oTwoCamera = test::referenceG2oTwoCameraPose();

double rotationDifferenceDeg(const SE3Quat& a, const SE3Quat& b) {
  return (a.inverse() * b).log().head<3>().norm() * 180.0 / M_PI;
}

struct Solved {
  SE3Quat T;
  double initial_chi2, final_chi2;
  int iterations;
  std::vector<double> per_iteration_chi2;
};

// to_the_floor: no early stop, LM runs until no step improves (g2o's way); otherwise the
// default stop, once less than 1e-10 of the starting chi2 is left to gain.
Solved solve(BundleMode mode, const SE3Quat& start, SolverBackend backend,
             bool to_the_floor = false) {
  const std::vector<PointPair> pairs = test::referencePairs(PNPBA_SHARED_DATA);
  SparseOptimizer optimizer;
  optimizer.setSolverBackend(backend);
  if (to_the_floor) {
    optimizer.options().min_relative_predicted_decrease = 0;
    optimizer.options().min_relative_accepted_decrease = 0;
  }
  PoseGraphOptions options;
  options.mode = mode;
  buildPoseGraph(optimizer, pairs, start, options);
  optimizer.initializeOptimization();
  optimizer.computeActiveErrors();
  Solved s;
  optimizer.setIterationCallback(
      [&s](const IterationStats& it) { s.per_iteration_chi2.push_back(it.chi2); });
  s.initial_chi2 = optimizer.chi2();
  s.iterations = optimizer.optimize(100);
  s.final_chi2 = optimizer.chi2();
  s.T = static_cast<VertexSE3Expmap*>(optimizer.vertex(PoseGraphIds::kPose))->estimate();
  return s;
}

class ReferenceParity : public ::testing::TestWithParam<SolverBackend> {
 protected:
  void SetUp() override { PNPBA_REQUIRE_SHARED_DATA(); }
};

TEST_P(ReferenceParity, PoseOnlyReachesTheLeastSquaresPose) {
  const Eigen::Matrix4d want = kLeastSquares.to_homogeneous_matrix();
  // Run to the floor, the pose is OpenCV's to 1e-8. The default stop leaves at most 1e-10 of
  // the starting chi2 (3e-8 px^2) to gain: along this problem's stiffest direction that is a
  // pose within about 1e-7 of the minimum.
  for (const bool to_the_floor : {true, false}) {
    const Solved s = solve(BundleMode::kPose, kEpnp, GetParam(), to_the_floor);
    EXPECT_NEAR(s.initial_chi2, 309.203253, 1e-5);  // the EPnP pose's cost, per the reference
    EXPECT_NEAR(s.final_chi2, 299.7635743, 1e-6);
    const Eigen::Matrix4d got = s.T.to_homogeneous_matrix();
    EXPECT_LE((got - want).cwiseAbs().maxCoeff(), to_the_floor ? 1e-8 : 1e-7) << got << "\nvs\n"
                                                                              << want;
  }
}

TEST_P(ReferenceParity, TextbookGraphAbsorbsTheErrorNearG2oPose) {
  const Solved s = solve(BundleMode::kTextbook, kLeastSquares, GetParam());
  EXPECT_NEAR(s.initial_chi2, 299.8675726, 1e-6);
  EXPECT_LT(s.final_chi2, 1e-6);
  // Under-determined: the answer depends on the LM path. The native back end follows g2o's.
  const bool native = GetParam() == SolverBackend::kNative;
  const double max_deg = native ? 0.01 : 0.2;
  const double max_m = native ? 1e-3 : 1e-2;
  EXPECT_LT(rotationDifferenceDeg(s.T, kG2oTextbook), max_deg);
  EXPECT_LT((s.T.translation() - kG2oTextbook.translation()).norm(), max_m);
  if (native) {
    // g2o's per-iteration chi2: 0.001139082306, 1.63e-9, 2.59e-15, ... Past ~1e-20 the values
    // are round-off, so only the first iterations are compared. The default stop ends after
    // the second (1.63e-9 left, the third would gain 1.6e-9 of a starting 299.9); run to the
    // floor, the third is g2o's too.
    ASSERT_GE(s.per_iteration_chi2.size(), 2u);
    EXPECT_NEAR(s.per_iteration_chi2[0], 0.001139082306, 1e-6 * 0.001139082306);
    EXPECT_NEAR(s.per_iteration_chi2[1], 1.63e-9, 0.01e-9);
    const Solved floor = solve(BundleMode::kTextbook, kLeastSquares, GetParam(), true);
    ASSERT_GE(floor.per_iteration_chi2.size(), 3u);
    EXPECT_NEAR(floor.per_iteration_chi2[1], 1.63e-9, 0.01e-9);
    EXPECT_NEAR(floor.per_iteration_chi2[2], 2.59e-15, 0.05e-15);
  }
}

TEST_P(ReferenceParity, TwoCameraGraphMatchesG2oChi2AndRotation) {
  const Solved s = solve(BundleMode::kTwoCamera, kLeastSquares, GetParam());
  EXPECT_NEAR(s.initial_chi2, 299.8786594, 1e-6);
  EXPECT_NEAR(s.final_chi2, 40.19222059, 1e-5);
  // Scale is unobservable here: compare rotation only.
  EXPECT_LT(rotationDifferenceDeg(s.T, kG2oTwoCamera), 0.01);
}

TEST_P(ReferenceParity, RgbdGraphFixesTheScale) {
  const Solved s = solve(BundleMode::kRgbd, kLeastSquares, GetParam());
  EXPECT_LT(s.final_chi2, s.initial_chi2);
  EXPECT_NEAR(s.T.translation().norm(), kLeastSquares.translation().norm(), 0.02);
  EXPECT_NEAR(kLeastSquares.translation().norm(), 0.1407, 1e-4);
}

INSTANTIATE_TEST_SUITE_P(Backends, ReferenceParity,
                         ::testing::Values(SolverBackend::kNative, SolverBackend::kCeres),
                         [](const auto& info) { return std::string(toString(info.param)); });

}  // namespace
}  // namespace pnpba
