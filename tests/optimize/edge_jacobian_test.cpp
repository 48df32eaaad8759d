// Every edge's analytic Jacobians (linearizeOplus) against central differences taken through
// the vertices' own update rule (pose: exp(delta) * T, point: X + delta), at 50 random
// configurations: rotations up to 90 degrees, points 0.3-20 m in front of the camera.
#include <gtest/gtest.h>

#include <functional>

#include "pnpba/optimize/camera_parameters.h"
#include "pnpba/optimize/edge_project_xyz2uv.h"
#include "pnpba/optimize/edge_se3_project_xyz.h"
#include "pnpba/optimize/edge_stereo_se3_project_xyz.h"
#include "random_poses.h"

namespace pnpba {
namespace {

constexpr int kConfigurations = 50;
constexpr double kMaxRelativeError = 1e-6;

// Central-difference Jacobian of edge.error() w.r.t. the tangent of `v`.
template <typename EdgeT>
Eigen::MatrixXd numericJacobian(EdgeT& edge, Vertex& v) {
  const double h = 1e-6;
  Eigen::MatrixXd J(EdgeT::Dimension, v.dimension());
  for (int k = 0; k < v.dimension(); ++k) {
    Eigen::VectorXd delta = Eigen::VectorXd::Zero(v.dimension());
    delta[k] = h;
    v.push();
    v.oplus(delta.data());
    edge.computeError();
    const Eigen::VectorXd plus = edge.error();
    v.pop();
    delta[k] = -h;
    v.push();
    v.oplus(delta.data());
    edge.computeError();
    const Eigen::VectorXd minus = edge.error();
    v.pop();
    J.col(k) = (plus - minus) / (2 * h);
  }
  return J;
}

double relativeError(const Eigen::MatrixXd& analytic, const Eigen::MatrixXd& numeric) {
  return (analytic - numeric).norm() / numeric.norm();
}

struct Scene {
  SE3Quat T;
  Eigen::Vector3d X;
};

// identity_rotation: the camera's rotation is exactly the identity, as a two-view graph's first
// camera is (the projection's shortcut for it; the pose's numeric Jacobian leaves it).
Scene randomScene(test::RandomScene& rnd, bool identity_rotation) {
  Scene s;
  s.T = rnd.pose(M_PI / 2, 2.0);
  if (identity_rotation) s.T = SE3Quat(Eigen::Quaterniond::Identity(), s.T.translation());
  s.X = rnd.pointInFront(s.T, 0.3, 20.0);
  return s;
}

// Checks a (point, pose) edge built by `make` at random configurations.
template <typename EdgeT>
void checkBinaryEdge(const std::function<void(EdgeT&, const Scene&, test::RandomScene&)>& make,
                     unsigned seed, bool identity_rotation = false) {
  test::RandomScene rnd(seed);
  double worst_point = 0, worst_pose = 0;
  for (int i = 0; i < kConfigurations; ++i) {
    const Scene s = randomScene(rnd, identity_rotation);
    VertexPointXYZ point;
    point.setEstimate(s.X);
    VertexSE3Expmap pose;
    pose.setEstimate(s.T);
    EdgeT edge;
    edge.setVertex(0, &point);
    edge.setVertex(1, &pose);
    make(edge, s, rnd);
    edge.linearizeOplus();
    worst_point =
        std::max(worst_point, relativeError(edge.jacobianOplusXi(), numericJacobian(edge, point)));
    worst_pose =
        std::max(worst_pose, relativeError(edge.jacobianOplusXj(), numericJacobian(edge, pose)));
  }
  EXPECT_LE(worst_point, kMaxRelativeError);
  EXPECT_LE(worst_pose, kMaxRelativeError);
}

// Checks a pose-only edge.
template <typename EdgeT>
void checkUnaryEdge(const std::function<void(EdgeT&, const Scene&, test::RandomScene&)>& make,
                    unsigned seed) {
  test::RandomScene rnd(seed);
  double worst = 0;
  for (int i = 0; i < kConfigurations; ++i) {
    const Scene s = randomScene(rnd, false);
    VertexSE3Expmap pose;
    pose.setEstimate(s.T);
    EdgeT edge;
    edge.setVertex(0, &pose);
    edge.Xw = s.X;
    make(edge, s, rnd);
    edge.linearizeOplus();
    worst = std::max(worst, relativeError(edge.jacobianOplusXi(), numericJacobian(edge, pose)));
  }
  EXPECT_LE(worst, kMaxRelativeError);
}

template <typename EdgeT>
void setPinhole(EdgeT& e, test::RandomScene& rnd) {
  e.fx = rnd.uniform(300, 900);
  e.fy = rnd.uniform(300, 900);
  e.cx = rnd.uniform(200, 400);
  e.cy = rnd.uniform(150, 300);
}

// Measurements a few pixels off the prediction, so the error is not zero.
template <typename EdgeT, typename Vec>
void setNoisyMeasurement(EdgeT& e, const Vec& predicted, test::RandomScene& rnd) {
  Vec m = predicted;
  for (int k = 0; k < m.size(); ++k) m[k] += rnd.normal(3.0);
  e.setMeasurement(m);
}

// Also at a camera with exactly the identity rotation, which the projection shortcuts.
TEST(EdgeJacobians, EdgeProjectXYZ2UV) {
  CameraParameters camera(520.9, Eigen::Vector2d(325.1, 249.7), 0);
  for (const bool identity_rotation : {false, true}) {
    checkBinaryEdge<EdgeProjectXYZ2UV>(
        [&camera](EdgeProjectXYZ2UV& e, const Scene& s, test::RandomScene& rnd) {
          e.resolveParameter(0, &camera);
          setNoisyMeasurement(e, camera.cam_map(s.T.map(s.X)), rnd);
          // The error against the projection written out, P = R X + t.
          e.computeError();
          const Eigen::Vector3d P = s.T.rotation().toRotationMatrix() * s.X + s.T.translation();
          const Eigen::Vector2d uv(520.9 * P.x() / P.z() + 325.1, 520.9 * P.y() / P.z() + 249.7);
          EXPECT_LT((e.error() - (e.measurement() - uv)).norm(), 1e-9);
        },
        identity_rotation ? 12 : 11, identity_rotation);
  }
}

TEST(EdgeJacobians, EdgeSE3ProjectXYZ) {
  checkBinaryEdge<EdgeSE3ProjectXYZ>(
      [](EdgeSE3ProjectXYZ& e, const Scene& s, test::RandomScene& rnd) {
        setPinhole(e, rnd);
        setNoisyMeasurement(e, e.cam_project(s.T.map(s.X)), rnd);
      },
      12);
}

TEST(EdgeJacobians, EdgeSE3ProjectXYZOnlyPose) {
  checkUnaryEdge<EdgeSE3ProjectXYZOnlyPose>(
      [](EdgeSE3ProjectXYZOnlyPose& e, const Scene& s, test::RandomScene& rnd) {
        setPinhole(e, rnd);
        setNoisyMeasurement(e, e.cam_project(s.T.map(s.X)), rnd);
      },
      13);
}

// Also at a camera with the identity rotation: the RGB-D graph's camera-1 edges.
TEST(EdgeJacobians, EdgeStereoSE3ProjectXYZ) {
  for (const bool identity_rotation : {false, true}) {
    checkBinaryEdge<EdgeStereoSE3ProjectXYZ>(
        [](EdgeStereoSE3ProjectXYZ& e, const Scene& s, test::RandomScene& rnd) {
          setPinhole(e, rnd);
          e.bf = rnd.uniform(20, 80);
          setNoisyMeasurement(e, e.cam_project(s.T.map(s.X)), rnd);
        },
        identity_rotation ? 15 : 14, identity_rotation);
  }
}

TEST(EdgeJacobians, EdgeStereoSE3ProjectXYZOnlyPose) {
  checkUnaryEdge<EdgeStereoSE3ProjectXYZOnlyPose>(
      [](EdgeStereoSE3ProjectXYZOnlyPose& e, const Scene& s, test::RandomScene& rnd) {
        setPinhole(e, rnd);
        e.bf = rnd.uniform(20, 80);
        setNoisyMeasurement(e, e.cam_project(s.T.map(s.X)), rnd);
      },
      15);
}

// The closed forms of DESIGN.md section 4 (g2o's linearizeOplus), written out independently.
TEST(EdgeJacobians, EdgeProjectXYZ2UVEqualsG2oClosedForm) {
  test::RandomScene rnd(16);
  CameraParameters camera(520.9, Eigen::Vector2d(325.1, 249.7), 0);
  for (int i = 0; i < kConfigurations; ++i) {
    const Scene s = randomScene(rnd, false);
    VertexPointXYZ point;
    point.setEstimate(s.X);
    VertexSE3Expmap pose;
    pose.setEstimate(s.T);
    EdgeProjectXYZ2UV e;
    e.setVertex(0, &point);
    e.setVertex(1, &pose);
    e.resolveParameter(0, &camera);
    e.linearizeOplus();
    const Eigen::Vector3d P = s.T.map(s.X);
    const double x = P.x(), y = P.y(), z = P.z(), f = camera.focal_length, z2 = z * z;
    Eigen::Matrix<double, 2, 6> Jpose;
    Jpose << f * x * y / z2, -f * (1 + x * x / z2), f * y / z, -f / z, 0, f * x / z2,  //
        f * (1 + y * y / z2), -f * x * y / z2, -f * x / z, 0, -f / z, f * y / z2;
    Eigen::Matrix<double, 2, 3> tmp;
    tmp << f, 0, -f * x / z, 0, f, -f * y / z;
    const Eigen::Matrix<double, 2, 3> Jpoint = -(1.0 / z) * tmp * s.T.rotation().toRotationMatrix();
    EXPECT_LE((e.jacobianOplusXj() - Jpose).norm(), 1e-12 * Jpose.norm());
    EXPECT_LE((e.jacobianOplusXi() - Jpoint).norm(), 1e-12 * Jpoint.norm());
  }
}

}  // namespace
}  // namespace pnpba
