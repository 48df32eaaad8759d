#include "pnpba/pipeline/depth_registration.h"

#include <omp.h>
#include <open3d/geometry/KDTreeSearchParam.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/pipelines/registration/Feature.h>
#include <open3d/pipelines/registration/Registration.h>
#include <open3d/pipelines/registration/TransformationEstimation.h>
#include <open3d/utility/Logging.h>
#include <open3d/utility/Random.h>

#include <Eigen/Eigenvalues>
#include <chrono>
#include <cmath>

#include "depth_cloud.h"
#include "pnpba/core/error.h"

namespace pnpba {

namespace {

namespace reg = open3d::pipelines::registration;
using open3d::geometry::KDTreeSearchParamHybrid;
using open3d::geometry::PointCloud;

// Down-sampled cloud with normals facing the camera and its FPFH descriptors.
struct Prepared {
  std::shared_ptr<PointCloud> cloud;
  std::shared_ptr<reg::Feature> fpfh;
};

Prepared prepare(const PointCloud& full, double voxel) {
  Prepared p;
  p.cloud = full.VoxelDownSample(voxel);
  p.cloud->EstimateNormals(KDTreeSearchParamHybrid(2.0 * voxel, 30));
  p.cloud->OrientNormalsTowardsCameraLocation(Eigen::Vector3d::Zero());
  p.fpfh = reg::ComputeFPFHFeature(*p.cloud, KDTreeSearchParamHybrid(5.0 * voxel, 100));
  return p;
}

// Open3D's RANSAC draws from one global generator on every OpenMP thread, and its ICP and
// normal estimation sum over OpenMP threads, so results depend on thread scheduling (measured:
// poses differing by 1e-8 between runs); one thread makes the registration a function of its
// input and seed alone.
class SingleThreadScope {
 public:
  SingleThreadScope() : previous_(omp_get_max_threads()) { omp_set_num_threads(1); }
  ~SingleThreadScope() { omp_set_num_threads(previous_); }

 private:
  int previous_;
};

}  // namespace

std::string DepthRegistrationOptions::validate() const {
  if (!(voxel_m > 0) || !std::isfinite(voxel_m)) return "registration voxel must be > 0";
  if (!(fine_voxel_m > 0) || !(fine_voxel_m <= voxel_m)) {
    return "registration fine voxel must be in (0, voxel]";
  }
  if (!(max_range_m > 0.1)) return "registration max range must be > 0.1 m";
  if (pixel_stride < 1) return "registration pixel stride must be >= 1";
  if (ransac_iterations < 1 || icp_iterations < 1) return "registration iterations must be >= 1";
  if (!(ransac_confidence > 0 && ransac_confidence < 1)) {
    return "registration confidence must be in (0, 1)";
  }
  return "";
}

DepthRegistration registerDepthImages(const cv::Mat& depth1, const cv::Mat& depth2,
                                      const PinholeCamera& camera, double depth_scale,
                                      const DepthRegistrationOptions& o) {
  const std::string problem = o.validate();
  if (!problem.empty()) throw Error(problem);
  if (depth1.type() != CV_16UC1 || depth2.type() != CV_16UC1) {
    throw Error("depth registration needs two 16-bit single-channel depth images");
  }
  const auto start = std::chrono::steady_clock::now();
  open3d::utility::SetVerbosityLevel(open3d::utility::VerbosityLevel::Error);

  const SingleThreadScope one_thread;
  DepthRegistration r;
  auto finish = [&](const std::string& failure) {
    r.failure = failure;
    r.time_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return r;
  };
  const std::shared_ptr<PointCloud> full1 =
      depthCloud(depth1, camera, depth_scale, o.pixel_stride, o.max_range_m);
  const std::shared_ptr<PointCloud> full2 =
      depthCloud(depth2, camera, depth_scale, o.pixel_stride, o.max_range_m);
  const Prepared source = prepare(*full1, o.voxel_m);
  const Prepared target = prepare(*full2, o.voxel_m);
  r.points1 = static_cast<int>(source.cloud->points_.size());
  r.points2 = static_cast<int>(target.cloud->points_.size());
  constexpr int kMinPoints = 50;
  if (r.points1 < kMinPoints || r.points2 < kMinPoints) {
    return finish("too little depth for registration (" + std::to_string(r.points1) + " and " +
                  std::to_string(r.points2) + " points)");
  }

  const double match_distance = 1.5 * o.voxel_m;
  const reg::CorrespondenceCheckerBasedOnEdgeLength edge_length(0.9);
  const reg::CorrespondenceCheckerBasedOnDistance distance(match_distance);
  reg::RegistrationResult coarse;
  {
    open3d::utility::random::Seed(o.seed);
    coarse = reg::RegistrationRANSACBasedOnFeatureMatching(
        *source.cloud, *target.cloud, *source.fpfh, *target.fpfh, /*mutual_filter=*/true,
        match_distance, reg::TransformationEstimationPointToPoint(false), 3,
        {edge_length, distance},
        reg::RANSACConvergenceCriteria(o.ransac_iterations, o.ransac_confidence));
  }
  if (coarse.correspondence_set_.size() < 3) return finish("registration found no overlap");

  // Point-to-plane ICP at the coarse voxel, then at the fine one (the coarse grid limits
  // accuracy to centimetres; the fine clouds are only built when RANSAC found something).
  const reg::RegistrationResult mid =
      reg::RegistrationICP(*source.cloud, *target.cloud, 0.8 * o.voxel_m, coarse.transformation_,
                           reg::TransformationEstimationPointToPlane(),
                           reg::ICPConvergenceCriteria(1e-6, 1e-6, o.icp_iterations));
  const auto fine1 = full1->VoxelDownSample(o.fine_voxel_m);
  const auto fine2 = full2->VoxelDownSample(o.fine_voxel_m);
  fine2->EstimateNormals(KDTreeSearchParamHybrid(3.0 * o.fine_voxel_m, 30));
  fine2->OrientNormalsTowardsCameraLocation(Eigen::Vector3d::Zero());
  const double icp_distance = 1.5 * o.fine_voxel_m;
  const reg::RegistrationResult fine =
      reg::RegistrationICP(*fine1, *fine2, icp_distance, mid.transformation_,
                           reg::TransformationEstimationPointToPlane(),
                           reg::ICPConvergenceCriteria(1e-6, 1e-6, o.icp_iterations));
  const Eigen::Matrix4d T = fine.transformation_;
  if (!T.allFinite()) return finish("registration diverged");
  r.T_21 = SE3Quat(T.topLeftCorner<3, 3>(), T.topRightCorner<3, 1>());
  r.fitness = fine.fitness_;
  r.inlier_rmse = fine.inlier_rmse_;

  // Open3D's information matrix is J^T J of point-to-point residuals over the correspondences,
  // in (rotation, translation) order for a left perturbation: ours. Scaled by the residual
  // variance it would be the inverse covariance if the residuals were independent; they are
  // not (voxel grids, smooth depth noise, surfaces seen partly), and on rendered rooms the
  // true error was 17-23x that 1-sigma. kSigmaInflation makes the reported 1-sigma honest.
  const Eigen::Matrix6d info =
      reg::GetInformationMatrixFromPointClouds(*fine1, *fine2, icp_distance, T);
  constexpr double kSigmaInflation = 20.0;
  const double sigma2 =
      kSigmaInflation * kSigmaInflation * std::max(r.inlier_rmse * r.inlier_rmse, 1e-6);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix6d> eig(info);
  if (eig.eigenvalues()(0) > 1e-9 * std::max(eig.eigenvalues()(5), 1e-300)) {
    r.covariance = sigma2 * info.inverse();
    r.covariance_ok = r.covariance.allFinite();
  }
  r.ok = true;
  return finish("");
}

}  // namespace pnpba
