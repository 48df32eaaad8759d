// The correspondence RANSAC on planted 3D-3D matches with known poses: it recovers a pose
// through 75 % outliers, returns a planted rival of similar support (and not a weak one), gives
// the same poses for any thread count, and rejects bad input clearly.
#include "pnpba/pipeline/correspondence_ransac.h"

#include <gtest/gtest.h>

#include <random>

#include "pnpba/core/error.h"

namespace pnpba {
namespace {

using Points = std::vector<Eigen::Vector3d>;

struct Matches {
  Points source, target;
};

SE3Quat motion(double deg, const Eigen::Vector3d& axis, const Eigen::Vector3d& t) {
  Vector6d xi;
  xi << axis.normalized() * deg * M_PI / 180.0, Eigen::Vector3d::Zero();
  const SE3Quat R = SE3Quat::exp(xi);
  return SE3Quat(R.rotation().toRotationMatrix(), t);
}

// n matches that T explains (1 cm noise) in a 6 x 3 x 6 m room.
void addInliers(const SE3Quat& T, int n, std::mt19937* rng, Matches* m) {
  std::uniform_real_distribution<double> x(-3, 3), y(-1.5, 1.5), z(1, 7);
  std::normal_distribution<double> noise(0, 0.01);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d X(x(*rng), y(*rng), z(*rng));
    m->source.push_back(X);
    m->target.push_back(T.map(X) + Eigen::Vector3d(noise(*rng), noise(*rng), noise(*rng)));
  }
}

// n matches to unrelated points.
void addOutliers(int n, std::mt19937* rng, Matches* m) {
  std::uniform_real_distribution<double> x(-3, 3), y(-1.5, 1.5), z(1, 7);
  for (int i = 0; i < n; ++i) {
    m->source.emplace_back(x(*rng), y(*rng), z(*rng));
    m->target.emplace_back(x(*rng), y(*rng), z(*rng));
  }
}

// Shuffles the matches together so that no block of the search sees only one kind.
void shuffle(std::mt19937* rng, Matches* m) {
  std::vector<size_t> order(m->source.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::shuffle(order.begin(), order.end(), *rng);
  Matches out;
  for (size_t i : order) {
    out.source.push_back(m->source[i]);
    out.target.push_back(m->target[i]);
  }
  *m = out;
}

double rotationDeg(const SE3Quat& a, const SE3Quat& b) {
  return (a.inverse() * b).log().head<3>().norm() * 180.0 / M_PI;
}

double translationM(const SE3Quat& a, const SE3Quat& b) {
  return (a.translation() - b.translation()).norm();
}

CorrespondenceRansacOptions options() {
  CorrespondenceRansacOptions o;
  o.inlier_distance_m = 0.05;
  return o;
}

TEST(CorrespondenceRansac, RecoversThePoseThroughManyOutliers) {
  for (unsigned seed : {1u, 2u, 3u, 4u, 5u}) {
    std::mt19937 rng(seed);
    const SE3Quat T = motion(35, {0.2, 1, -0.1}, {0.8, -0.1, 0.5});
    Matches m;
    addInliers(T, 150, &rng, &m);
    addOutliers(450, &rng, &m);
    shuffle(&rng, &m);
    CorrespondenceRansacStats stats;
    const std::vector<RigidCandidate> c = ransacRigidPoses(m.source, m.target, options(), &stats);
    ASSERT_FALSE(c.empty()) << "seed " << seed;
    EXPECT_LT(rotationDeg(c[0].T_21, T), 0.5) << "seed " << seed;
    EXPECT_LT(translationM(c[0].T_21, T), 0.02) << "seed " << seed;
    EXPECT_GE(c[0].support, 140) << "seed " << seed;
    EXPECT_LE(c[0].support, 150 + 10) << "seed " << seed;  // outliers land by chance only
    // The confidence stop ends the search long before its cap (a quarter are inliers).
    EXPECT_LT(stats.iterations, options().max_iterations) << "seed " << seed;
  }
}

TEST(CorrespondenceRansac, ReturnsARivalOfSimilarSupportBestFirst) {
  std::mt19937 rng(11);
  const SE3Quat T_a = motion(20, {0, 1, 0}, {0.5, 0, 0.2});
  const SE3Quat T_b = motion(-15, {0.1, 1, 0}, {-1.5, 0, 0.4});  // a slide and a turn away
  Matches m;
  addInliers(T_a, 120, &rng, &m);
  addInliers(T_b, 90, &rng, &m);
  addOutliers(200, &rng, &m);
  shuffle(&rng, &m);
  const std::vector<RigidCandidate> c = ransacRigidPoses(m.source, m.target, options());
  ASSERT_EQ(c.size(), 2u);
  EXPECT_LT(rotationDeg(c[0].T_21, T_a), 0.5);
  EXPECT_LT(translationM(c[0].T_21, T_a), 0.02);
  EXPECT_LT(rotationDeg(c[1].T_21, T_b), 0.5);
  EXPECT_LT(translationM(c[1].T_21, T_b), 0.02);
  EXPECT_GT(c[0].support, c[1].support);
}

TEST(CorrespondenceRansac, LeavesOutARivalWithLittleSupport) {
  std::mt19937 rng(12);
  const SE3Quat T_a = motion(20, {0, 1, 0}, {0.5, 0, 0.2});
  const SE3Quat T_b = motion(-15, {0.1, 1, 0}, {-1.5, 0, 0.4});
  Matches m;
  addInliers(T_a, 120, &rng, &m);
  addInliers(T_b, 30, &rng, &m);  // a quarter of the best's support, below rival_support
  addOutliers(200, &rng, &m);
  shuffle(&rng, &m);
  const std::vector<RigidCandidate> c = ransacRigidPoses(m.source, m.target, options());
  ASSERT_EQ(c.size(), 1u);
  EXPECT_LT(translationM(c[0].T_21, T_a), 0.02);
}

TEST(CorrespondenceRansac, SamePosesForAnyThreadCount) {
  std::mt19937 rng(13);
  Matches m;
  addInliers(motion(40, {0.3, 1, 0.2}, {1.0, 0.2, -0.3}), 80, &rng, &m);
  addInliers(motion(5, {0, 1, 0}, {-1.0, 0, 0}), 60, &rng, &m);
  addOutliers(400, &rng, &m);
  shuffle(&rng, &m);
  CorrespondenceRansacOptions one = options(), two = options();
  one.threads = 1;
  two.threads = 2;
  const std::vector<RigidCandidate> a = ransacRigidPoses(m.source, m.target, one);
  const std::vector<RigidCandidate> b = ransacRigidPoses(m.source, m.target, two);
  const std::vector<RigidCandidate> again = ransacRigidPoses(m.source, m.target, two);
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(b.size(), again.size());
  ASSERT_FALSE(a.empty());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].support, b[i].support);
    EXPECT_EQ(a[i].T_21.to_homogeneous_matrix(), b[i].T_21.to_homogeneous_matrix());
    EXPECT_EQ(b[i].T_21.to_homogeneous_matrix(), again[i].T_21.to_homogeneous_matrix());
  }
}

TEST(CorrespondenceRansac, NothingFromTooFewOrUnrelatedMatches) {
  EXPECT_TRUE(ransacRigidPoses({{0, 0, 1}, {1, 0, 1}}, {{0, 0, 1}, {1, 0, 1}}, options()).empty());
  std::mt19937 rng(14);
  Matches m;
  addOutliers(40, &rng, &m);
  CorrespondenceRansacOptions o = options();
  o.inlier_distance_m = 0.001;  // no three unrelated matches agree this closely
  EXPECT_TRUE(ransacRigidPoses(m.source, m.target, o).empty());
}

TEST(CorrespondenceRansac, RejectsBadInputWithAClearMessage) {
  try {
    ransacRigidPoses({{0, 0, 1}}, {}, options());
    FAIL() << "sizes that differ were accepted";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "correspondence RANSAC: 1 source and 0 target points");
  }
  CorrespondenceRansacOptions o = options();
  o.confidence = 1.0;
  EXPECT_EQ(o.validate(), "correspondence RANSAC confidence must be in (0, 1)");
  EXPECT_THROW(ransacRigidPoses({}, {}, o), Error);
  o = options();
  o.threads = 0;
  EXPECT_EQ(o.validate(), "correspondence RANSAC threads must be >= 1");
}

}  // namespace
}  // namespace pnpba
