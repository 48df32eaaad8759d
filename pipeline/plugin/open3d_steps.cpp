// The Open3D plugin: the depth-only registration's steps that are Open3D's own (its RANSAC and
// fast global registration, point-to-plane ICP, the information matrix), in a module opened only
// when a registration's options ask for one of them (open3d_plugin_api.h). The registration's
// default steps are pnpba's (pipeline/src/registration/) and never open it.
#include <omp.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/pipelines/registration/FastGlobalRegistration.h>
#include <open3d/pipelines/registration/Feature.h>
#include <open3d/pipelines/registration/Registration.h>
#include <open3d/pipelines/registration/TransformationEstimation.h>
#include <open3d/utility/Logging.h>
#include <open3d/utility/Random.h>

#include <exception>
#include <limits>
#include <mutex>
#include <type_traits>

#include "../src/open3d_plugin_api.h"

namespace {

namespace reg = open3d::pipelines::registration;
using open3d::geometry::PointCloud;

// Open3D's RANSAC draws from one global generator on every OpenMP thread, and its ICP sums over
// OpenMP threads, so results depend on thread scheduling (measured: poses differing by 1e-8
// between runs); one thread makes each step a function of its input and seed alone. Some of
// Open3D's loops ask for every processor by a num_threads clause, which the thread count does
// not cap: no active parallel level does (this thread's setting).
class SingleThreadScope {
 public:
  SingleThreadScope() : threads_(omp_get_max_threads()), levels_(omp_get_max_active_levels()) {
    omp_set_num_threads(1);
    omp_set_max_active_levels(0);
  }
  ~SingleThreadScope() {
    omp_set_max_active_levels(levels_);
    omp_set_num_threads(threads_);
  }

 private:
  int threads_, levels_;
};

PointCloud open3dCloud(const pnpba::Cloud& cloud) {
  PointCloud out(cloud.points);
  out.normals_ = cloud.normals;
  return out;
}

reg::Feature open3dFeature(const pnpba::FpfhRows& rows) {
  reg::Feature f;
  f.data_ = rows;
  return f;
}

void quiet() { open3d::utility::SetVerbosityLevel(open3d::utility::VerbosityLevel::Error); }

}  // namespace

extern "C" __attribute__((visibility("default"))) bool pnpba_open3d_global_search_v3(
    const pnpba::Cloud* source_in, const pnpba::Cloud* target_in,
    const pnpba::FpfhRows* source_fpfh, const pnpba::FpfhRows* target_fpfh, bool fast,
    double match_distance, int iterations, double confidence, int seed, Eigen::Matrix4d* T) {
  static_assert(std::is_same_v<decltype(pnpba_open3d_global_search_v3), pnpba::Open3dGlobalSearch>);
  try {
    quiet();
    const SingleThreadScope one_thread;
    const PointCloud source = open3dCloud(*source_in), target = open3dCloud(*target_in);
    const reg::Feature fs = open3dFeature(*source_fpfh), ft = open3dFeature(*target_fpfh);
    // Open3D's random generator is one for the process: registrations running at once (the
    // batch runner's threads) would draw from it in turn and lose their determinism.
    static std::mutex random_generator;
    const std::lock_guard<std::mutex> lock(random_generator);
    open3d::utility::random::Seed(seed);
    reg::RegistrationResult coarse;
    if (fast) {
      reg::FastGlobalRegistrationOption fgr;
      fgr.use_absolute_scale_ = true;
      fgr.maximum_correspondence_distance_ = match_distance;
      coarse = reg::FastGlobalRegistrationBasedOnFeatureMatching(source, target, fs, ft, fgr);
      coarse = reg::EvaluateRegistration(source, target, match_distance, coarse.transformation_);
    } else {
      const reg::CorrespondenceCheckerBasedOnEdgeLength edge_length(0.9);
      const reg::CorrespondenceCheckerBasedOnDistance distance(match_distance);
      coarse = reg::RegistrationRANSACBasedOnFeatureMatching(
          source, target, fs, ft, /*mutual_filter=*/true, match_distance,
          reg::TransformationEstimationPointToPoint(false), 3, {edge_length, distance},
          reg::RANSACConvergenceCriteria(iterations, confidence));
    }
    *T = coarse.transformation_;
    return coarse.correspondence_set_.size() >= 3;
  } catch (const std::exception&) {
    return false;
  }
}

extern "C" __attribute__((visibility("default"))) void pnpba_open3d_icp_v3(
    const pnpba::Cloud* source, const pnpba::Cloud* target, double distance,
    const Eigen::Matrix4d* initial, int iterations, Eigen::Matrix4d* T, double* fitness,
    double* inlier_rmse) {
  static_assert(std::is_same_v<decltype(pnpba_open3d_icp_v3), pnpba::Open3dIcp>);
  *T = Eigen::Matrix4d::Constant(std::numeric_limits<double>::quiet_NaN());  // on a failure
  *fitness = *inlier_rmse = 0;
  try {
    quiet();
    const SingleThreadScope one_thread;
    const reg::RegistrationResult r =
        reg::RegistrationICP(open3dCloud(*source), open3dCloud(*target), distance, *initial,
                             reg::TransformationEstimationPointToPlane(),
                             reg::ICPConvergenceCriteria(1e-6, 1e-6, iterations));
    *T = r.transformation_;
    *fitness = r.fitness_;
    *inlier_rmse = r.inlier_rmse_;
  } catch (const std::exception&) {
  }
}

extern "C" __attribute__((visibility("default"))) void pnpba_open3d_information_v3(
    const pnpba::Cloud* source, const pnpba::Cloud* target, double distance,
    const Eigen::Matrix4d* T, Eigen::Matrix<double, 6, 6>* information) {
  static_assert(std::is_same_v<decltype(pnpba_open3d_information_v3), pnpba::Open3dInformation>);
  information->setZero();  // on a failure: no covariance
  try {
    quiet();
    const SingleThreadScope one_thread;
    *information = reg::GetInformationMatrixFromPointClouds(open3dCloud(*source),
                                                            open3dCloud(*target), distance, *T);
  } catch (const std::exception&) {
  }
}
