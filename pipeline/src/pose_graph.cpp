#include "pnpba/pipeline/pose_graph.h"

#include <cmath>
#include <memory>
#include <string>

#include "pnpba/core/error.h"
#include "pnpba/optimize/camera_parameters.h"
#include "pnpba/optimize/edge_project_xyz2uv.h"
#include "pnpba/optimize/edge_se3_project_xyz.h"
#include "pnpba/optimize/edge_stereo_se3_project_xyz.h"

namespace pnpba {

const char* toString(BundleMode mode) {
  switch (mode) {
    case BundleMode::kNone:
      return "none";
    case BundleMode::kPose:
      return "pose";
    case BundleMode::kTextbook:
      return "textbook";
    case BundleMode::kTwoCamera:
      return "two-camera";
    case BundleMode::kRgbd:
      return "rgbd";
  }
  return "?";
}

BundleMode parseBundleMode(const std::string& name) {
  for (BundleMode m : {BundleMode::kNone, BundleMode::kPose, BundleMode::kTextbook,
                       BundleMode::kTwoCamera, BundleMode::kRgbd}) {
    if (name == toString(m)) return m;
  }
  throw Error("unknown BA mode '" + name + "' (expected none, pose, textbook, two-camera or rgbd)");
}

std::string PoseGraphOptions::validate() const {
  const std::string camera = intrinsics.validate();
  if (!camera.empty()) return "intrinsics: " + camera;
  if (!(pixel_sigma > 0)) return "pixel_sigma must be > 0";
  if (!(depth_noise_k > 0)) return "depth_noise_k must be > 0";
  if (!(virtual_baseline > 0)) return "virtual_baseline must be > 0";
  if (!(depth2_gate_chi2 > 0)) return "depth2_gate_chi2 must be > 0";
  return "";
}

namespace {

// Information of (u, v, u_r = u - bf/z) for independent noise on u, v (sigma_px) and on the
// disparity bf/z (sigma_d = bf k, from sigma_z = k z^2): u and u_r share u's noise.
Eigen::Matrix3d stereoInformation(double sigma_px, double sigma_d) {
  const double s2 = sigma_px * sigma_px;
  Eigen::Matrix3d cov;
  cov << s2, 0, s2, 0, s2, 0, s2, 0, s2 + sigma_d * sigma_d;
  return cov.inverse();
}

// chi2 95% quantiles by edge dimension (ORB-SLAM's Huber widths).
constexpr double kChi2_95_2dof = 5.991;
constexpr double kChi2_95_3dof = 7.815;

void addKernel(Edge* e, bool robust) {
  if (!robust) return;
  const double chi2 = e->dimension() == 3 ? kChi2_95_3dof : kChi2_95_2dof;
  e->setRobustKernel(new RobustKernelHuber(std::sqrt(chi2)));
}

// The textbook's edge: point observed at `uv` by `camera` through CameraParameters 0.
void addTextbookEdge(SparseOptimizer& optimizer, int id, VertexPointXYZ* point,
                     VertexSE3Expmap* camera, const Eigen::Vector2d& uv, double info_px,
                     bool robust) {
  auto* e = new EdgeProjectXYZ2UV();
  e->setId(id);
  e->setVertex(0, point);
  e->setVertex(1, camera);
  e->setMeasurement(uv);
  e->setParameterId(0, 0);
  e->setInformation(info_px * Eigen::Matrix2d::Identity());
  addKernel(e, robust);
  optimizer.addEdge(e);
}

// The pixel-and-depth observation by a camera: (u, v, u - bf/z).
EdgeStereoSE3ProjectXYZ* makeStereoEdge(int id, VertexPointXYZ* point, VertexSE3Expmap* camera,
                                        const Eigen::Vector2d& uv, double z, double bf,
                                        const Eigen::Matrix3d& information, const PinholeCamera& k,
                                        bool robust) {
  auto* e = new EdgeStereoSE3ProjectXYZ();
  e->setId(id);
  e->setVertex(0, point);
  e->setVertex(1, camera);
  e->setMeasurement(Eigen::Vector3d(uv.x(), uv.y(), uv.x() - bf / z));
  e->setInformation(information);
  e->fx = k.fx, e->fy = k.fy, e->cx = k.cx, e->cy = k.cy, e->bf = bf;
  addKernel(e, robust);
  return e;
}

// Whether depth 2 agrees with the start pose T_21 (chi2 of camera 2's pixel-and-depth error
// within the gate): only then does camera 2's observation carry it.
bool depth2Agrees(const PointPair& pair, const SE3Quat& T_21, double bf,
                  const Eigen::Matrix3d& information, const PoseGraphOptions& options) {
  if (!std::isfinite(pair.depth_2) || !(pair.depth_2 > 0)) return false;
  EdgeStereoSE3ProjectXYZ e;
  const PinholeCamera& k = options.intrinsics;
  e.fx = k.fx, e.fy = k.fy, e.cx = k.cx, e.cy = k.cy, e.bf = bf;
  e.setMeasurement(
      Eigen::Vector3d(pair.uv_2.x(), pair.uv_2.y(), pair.uv_2.x() - bf / pair.depth_2));
  Eigen::Vector3d error;
  e.evaluate(pair.X_1, T_21, &error, nullptr, nullptr);
  return error.dot(information * error) <= options.depth2_gate_chi2;
}

// rgbd mode: camera 2's observation with depth 2, when the pair has one and it agrees with
// the start pose (gate). Returns false when no edge was added.
bool addDepth2Edge(SparseOptimizer& optimizer, int& edge_id, VertexPointXYZ* point,
                   VertexSE3Expmap* pose, const PointPair& pair, const SE3Quat& T_21, double bf,
                   const Eigen::Matrix3d& information, const PoseGraphOptions& options) {
  if (options.mode != BundleMode::kRgbd || !depth2Agrees(pair, T_21, bf, information, options)) {
    return false;
  }
  optimizer.addEdge(makeStereoEdge(edge_id++, point, pose, pair.uv_2, pair.depth_2, bf, information,
                                   options.intrinsics, options.robust));
  return true;
}

}  // namespace

PoseGraphIds buildPoseGraph(SparseOptimizer& optimizer, const std::vector<PointPair>& pairs,
                            const SE3Quat& T_21, const PoseGraphOptions& options) {
  const std::string problem = options.validate();
  if (!problem.empty()) throw Error("pose graph options: " + problem);
  if (options.mode == BundleMode::kNone) throw Error("BA mode none builds no graph");
  const PinholeCamera& k = options.intrinsics;
  // Information of a pixel observed with relative noise `sigma`.
  auto info_px = [&options](double sigma) {
    const double s = options.pixel_sigma * sigma;
    return 1.0 / (s * s);
  };
  PoseGraphIds ids;

  auto* pose = new VertexSE3Expmap();
  pose->setId(PoseGraphIds::kPose);
  pose->setEstimate(T_21);
  optimizer.addVertex(pose);

  if (options.mode == BundleMode::kPose) {
    for (size_t i = 0; i < pairs.size(); ++i) {
      auto* e = new EdgeSE3ProjectXYZOnlyPose();
      e->setId(static_cast<int>(i));
      e->setVertex(0, pose);
      e->setMeasurement(pairs[i].uv_2);
      e->setInformation(info_px(pairs[i].sigma_2) * Eigen::Matrix2d::Identity());
      e->Xw = pairs[i].X_1;
      e->fx = k.fx, e->fy = k.fy, e->cx = k.cx, e->cy = k.cy;
      addKernel(e, options.robust);
      optimizer.addEdge(e);
    }
    return ids;
  }

  const bool textbook_edges =
      options.mode == BundleMode::kTextbook || options.mode == BundleMode::kTwoCamera;
  if (textbook_edges) {
    auto* camera = new CameraParameters(k.fx, Eigen::Vector2d(k.cx, k.cy), 0);
    camera->setId(0);
    optimizer.addParameter(camera);
  }
  VertexSE3Expmap* camera1 = nullptr;
  if (options.mode != BundleMode::kTextbook) {
    camera1 = new VertexSE3Expmap();
    ids.camera1 = static_cast<int>(pairs.size()) + 1;
    camera1->setId(ids.camera1);
    camera1->setFixed(true);
    optimizer.addVertex(camera1);
  }
  const double bf = options.virtual_baseline * k.fx;
  const double sigma_d = bf * options.depth_noise_k;
  if (options.mode == BundleMode::kRgbd) ids.depth2.assign(pairs.size(), 0);

  int edge_id = 0;
  for (size_t i = 0; i < pairs.size(); ++i) {
    auto* point = new VertexPointXYZ();
    point->setId(ids.first_point + static_cast<int>(i));
    point->setEstimate(pairs[i].X_1);
    point->setMarginalized(true);
    optimizer.addVertex(point);

    // Camera 2 observes the point.
    if (textbook_edges) {
      addTextbookEdge(optimizer, edge_id++, point, pose, pairs[i].uv_2, info_px(pairs[i].sigma_2),
                      options.robust);
    } else if (addDepth2Edge(optimizer, edge_id, point, pose, pairs[i], T_21, bf,
                             stereoInformation(options.pixel_sigma * pairs[i].sigma_2, sigma_d),
                             options)) {
      ids.depth2[i] = 1;
    } else {
      auto* e = new EdgeSE3ProjectXYZ();
      e->setId(edge_id++);
      e->setVertex(0, point);
      e->setVertex(1, pose);
      e->setMeasurement(pairs[i].uv_2);
      e->setInformation(info_px(pairs[i].sigma_2) * Eigen::Matrix2d::Identity());
      e->fx = k.fx, e->fy = k.fy, e->cx = k.cx, e->cy = k.cy;
      addKernel(e, options.robust);
      optimizer.addEdge(e);
    }
    if (camera1 == nullptr) continue;

    // Camera 1 observes it too: by pixel (two-camera) or by pixel and depth (rgbd).
    if (options.mode == BundleMode::kTwoCamera) {
      addTextbookEdge(optimizer, edge_id++, point, camera1, pairs[i].uv_1,
                      info_px(pairs[i].sigma_1), options.robust);
    } else {
      const Eigen::Matrix3d info =
          stereoInformation(options.pixel_sigma * pairs[i].sigma_1, sigma_d);
      optimizer.addEdge(makeStereoEdge(edge_id++, point, camera1, pairs[i].uv_1, pairs[i].X_1.z(),
                                       bf, info, k, options.robust));
    }
  }
  return ids;
}

RgbdPairProblem rgbdPairProblem(const std::vector<PointPair>& pairs, const SE3Quat& T_21,
                                const PoseGraphOptions& options, std::vector<char>* depth2) {
  const std::string problem = options.validate();
  if (!problem.empty()) throw Error("pose graph options: " + problem);
  if (options.mode != BundleMode::kRgbd) throw Error("rgbdPairProblem: the rgbd mode's graph");
  const PinholeCamera& k = options.intrinsics;
  const double bf = options.virtual_baseline * k.fx;
  const double sigma_d = bf * options.depth_noise_k;
  RgbdPairProblem out;
  out.camera = {k.fx, k.fy, k.cx, k.cy, bf};
  if (options.robust) {
    out.huber_delta_stereo = std::sqrt(kChi2_95_3dof);
    out.huber_delta_pixel = std::sqrt(kChi2_95_2dof);
  }
  depth2->assign(pairs.size(), 0);
  out.observations.reserve(pairs.size());
  for (size_t i = 0; i < pairs.size(); ++i) {
    const PointPair& pair = pairs[i];
    RgbdPairObservation o;
    o.by_camera1 = Eigen::Vector3d(pair.uv_1.x(), pair.uv_1.y(), pair.uv_1.x() - bf / pair.X_1.z());
    o.information1 = stereoInformation(options.pixel_sigma * pair.sigma_1, sigma_d);
    const Eigen::Matrix3d information2 =
        stereoInformation(options.pixel_sigma * pair.sigma_2, sigma_d);
    if (depth2Agrees(pair, T_21, bf, information2, options)) {
      o.depth2 = true;
      o.by_camera2 =
          Eigen::Vector3d(pair.uv_2.x(), pair.uv_2.y(), pair.uv_2.x() - bf / pair.depth_2);
      o.information2 = information2;
      (*depth2)[i] = 1;
    } else {
      o.by_camera2 = Eigen::Vector3d(pair.uv_2.x(), pair.uv_2.y(), 0.0);
      const double s = options.pixel_sigma * pair.sigma_2;
      o.pixel_information2 = 1.0 / (s * s);
    }
    out.observations.push_back(o);
  }
  return out;
}

bool rgbdPoseCovariances(const std::vector<PointPair>& pairs, const std::vector<char>& depth2,
                         const SE3Quat& T_21, const PoseGraphOptions& options,
                         const std::vector<double>& depth_noise_k,
                         std::vector<Eigen::Matrix<double, 6, 6>>* covariances) {
  using Matrix36 = Eigen::Matrix<double, 3, 6>;
  using Matrix6 = Eigen::Matrix<double, 6, 6>;
  using Row3 = Eigen::Matrix<double, 1, 3>;
  using Row6 = Eigen::Matrix<double, 1, 6>;
  const PinholeCamera& k = options.intrinsics;
  const double bf = options.virtual_baseline * k.fx;
  EdgeStereoSE3ProjectXYZ stereo;
  stereo.fx = k.fx, stereo.fy = k.fy, stereo.cx = k.cx, stereo.cy = k.cy, stereo.bf = bf;
  EdgeSE3ProjectXYZ mono;
  mono.fx = k.fx, mono.fy = k.fy, mono.cx = k.cx, mono.cy = k.cy;
  const SE3Quat identity;
  const size_t settings = depth_noise_k.size();
  std::vector<double> disparity_weight(settings);  // 1 / sigma_d^2 per setting
  for (size_t c = 0; c < settings; ++c) {
    const double sigma_d = bf * depth_noise_k[c];
    disparity_weight[c] = 1.0 / (sigma_d * sigma_d);
  }
  // With (u, v, u_r) read as (u, v, u - u_r), a pixel and a disparity of independent noise,
  // every block is a pixel part plus a disparity part times 1 / sigma_d^2: the pose blocks sum
  // over the points once, and only the points' elimination is done per setting.
  Matrix6 pose_pixel = Matrix6::Zero(), pose_disparity = Matrix6::Zero();
  std::vector<Matrix6> eliminated(settings, Matrix6::Zero());
  for (size_t i = 0; i < pairs.size(); ++i) {
    const PointPair& p = pairs[i];
    const bool with_depth2 = i < depth2.size() && depth2[i];
    const double w1 = 1.0 / std::pow(options.pixel_sigma * p.sigma_1, 2);
    const double w2 = 1.0 / std::pow(options.pixel_sigma * p.sigma_2, 2);
    Eigen::Vector3d stereo_error;
    EdgeStereoSE3ProjectXYZ::JacobianXiType point1;
    stereo.evaluate(p.X_1, identity, &stereo_error, &point1, nullptr);  // camera 1 is fixed
    const Row3 disparity1 = point1.row(0) - point1.row(2);
    Eigen::Matrix3d point_pixel = w1 * point1.topRows<2>().transpose() * point1.topRows<2>();
    Eigen::Matrix3d point_disparity = disparity1.transpose() * disparity1;
    Matrix36 cross_pixel, cross_disparity = Matrix36::Zero();
    if (with_depth2) {
      EdgeStereoSE3ProjectXYZ::JacobianXiType point2;
      EdgeStereoSE3ProjectXYZ::JacobianXjType pose2;
      stereo.evaluate(p.X_1, T_21, &stereo_error, &point2, &pose2);
      const auto point2_pixel = point2.topRows<2>();
      const auto pose2_pixel = pose2.topRows<2>();
      const Row3 point2_disparity = point2.row(0) - point2.row(2);
      const Row6 pose2_disparity = pose2.row(0) - pose2.row(2);
      point_pixel += w2 * point2_pixel.transpose() * point2_pixel;
      point_disparity += point2_disparity.transpose() * point2_disparity;
      cross_pixel = w2 * point2_pixel.transpose() * pose2_pixel;
      cross_disparity = point2_disparity.transpose() * pose2_disparity;
      pose_pixel += w2 * pose2_pixel.transpose() * pose2_pixel;
      pose_disparity += pose2_disparity.transpose() * pose2_disparity;
    } else {
      Eigen::Vector2d mono_error;
      EdgeSE3ProjectXYZ::JacobianXiType point2;
      EdgeSE3ProjectXYZ::JacobianXjType pose2;
      mono.evaluate(p.X_1, T_21, &mono_error, &point2, &pose2);
      point_pixel += w2 * point2.transpose() * point2;
      cross_pixel = w2 * point2.transpose() * pose2;
      pose_pixel += w2 * pose2.transpose() * pose2;
    }
    for (size_t c = 0; c < settings; ++c) {
      const Eigen::Matrix3d H_point = point_pixel + disparity_weight[c] * point_disparity;
      const Matrix36 H_cross = cross_pixel + disparity_weight[c] * cross_disparity;
      // The point eliminated: its Schur complement on the pose.
      eliminated[c].noalias() += H_cross.transpose() * (H_point.inverse() * H_cross);
    }
  }
  covariances->assign(settings, Matrix6::Zero());
  for (size_t c = 0; c < settings; ++c) {
    const Matrix6 S = pose_pixel + disparity_weight[c] * pose_disparity - eliminated[c];
    const Eigen::LDLT<Matrix6> ldlt(S);
    if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0)) return false;
    (*covariances)[c] = ldlt.solve(Matrix6::Identity());
    if (!(*covariances)[c].allFinite()) return false;
  }
  return true;
}

}  // namespace pnpba
