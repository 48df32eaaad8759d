// The depth-only registration of depth_registration.h: both depths back-projected and
// down-sampled, normals and FPFH descriptors, a search over their matches for one pose or every
// rival, their overlap measured; Open3D's own global search, ICP and covariance only where the
// options ask for them, through the plugin's steps (open3d_plugin_api.h).
#include "registration.h"

#include <oneapi/tbb/parallel_invoke.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <vector>

#include "depth_cloud.h"
#include "fpfh.h"
#include "nearest_point_grid.h"
#include "pnpba/pipeline/correspondence_ransac.h"
#include "pnpba/pipeline/nearest_descriptors.h"
#include "point_normals.h"
#include "voxel_grid.h"

namespace pnpba {

namespace {

// Down-sampled cloud with normals facing the camera and its FPFH descriptors: float rows for the
// project's matching, and the double rows only for Open3D's own searches (open3d-ransac, fast).
struct Prepared {
  std::shared_ptr<Cloud> cloud;
  FpfhRows fpfh;
  Eigen::MatrixXf descriptors;  // 33 x n: one descriptor's floats after another
};

Prepared prepare(Cloud down_sampled, double voxel, int fpfh_neighbours, bool open3d_feature) {
  Prepared p;
  p.cloud = std::make_shared<Cloud>(std::move(down_sampled));
  estimateNormals(p.cloud.get(), 2.0 * voxel, 30);
  orientNormalsTowardsCamera(p.cloud.get());
  // Open3D's FPFH descriptors (fpfh.h), in 25-45 ms a rendered room's cloud where Open3D's tensor
  // ComputeFPFHFeature took 70-90 and its legacy one 150-180.
  const Eigen::Matrix<double, 33, Eigen::Dynamic> rows =
      fpfhDescriptors(*p.cloud, fpfh_neighbours, 5.0 * voxel);
  if (open3d_feature) p.fpfh = rows;
  // Matched in single precision: the same registration as in double on every rendered and
  // fr3_cabinet pair of registration_bench.
  p.descriptors = rows.cast<float>();
  return p;
}

// Depth 1 described for a registration, kept by the caller for the depth's next registrations
// as frame 1 (a key frame's): everything the registration derives from depth 1 alone. Read
// only once made, so estimates on several threads may share it.
struct DescribedDepth1 {
  std::shared_ptr<Cloud> full;  // the back-projection (the fine ICP stage down-samples it)
  double voxel = 0;
  Prepared prepared;
};

// The voxel: voxel_depth_fraction of cloud 1's median depth, at most voxel_m (and grown past
// max_points below). Close scenes (a cabinet at 1.3 m) get a finer voxel than a room; the ceiling
// keeps the descriptors sharp enough in a room (at 0.2 m the rendered cabinet by a wall 4 m away
// gave 180-degree flips and slides along the wall the evidence could not tell apart).
// pipeline/src/registration_work.cpp predicts the clouds' sizes by the same rule for a time
// budget: a change here belongs there too.
double registrationVoxel(const Cloud& cloud1, const DepthRegistrationOptions& o) {
  if (!(o.voxel_depth_fraction > 0) || cloud1.points.empty()) return o.voxel_m;
  std::vector<double> z;
  z.reserve(cloud1.points.size());
  for (const Eigen::Vector3d& p : cloud1.points) z.push_back(p.z());
  std::nth_element(z.begin(), z.begin() + z.size() / 2, z.end());
  return std::min(o.voxel_m, o.voxel_depth_fraction * z[z.size() / 2]);
}

// Putative correspondences: each cloud-1 point's nearest cloud-2 point in FPFH space, kept where
// the match is mutual; when fewer than 9 are, every one-way match (Open3D's mutual filter does
// the same).
void fpfhMatches(const Prepared& source, const Prepared& target, std::vector<Eigen::Vector3d>* s,
                 std::vector<Eigen::Vector3d>* t) {
  // Exact nearest neighbours both ways in one brute-force pass (nearest_descriptors.h): 13-18 ms
  // for the rendered rooms' 5000 x 5000 descriptors where nanoflann's exact k-d tree took 45-60.
  const Eigen::MatrixXf& a = source.descriptors;
  const Eigen::MatrixXf& b = target.descriptors;
  const NearestBothWays nearest = nearestBothWays(a.data(), static_cast<int>(a.cols()), b.data(),
                                                  static_cast<int>(b.cols()), 33);
  const std::vector<int>& forward = nearest.a_to_b;
  const std::vector<int>& backward = nearest.b_to_a;
  std::vector<int> mutual;
  for (int i = 0; i < static_cast<int>(forward.size()); ++i) {
    if (backward[forward[i]] == i) mutual.push_back(i);
  }
  const bool use_mutual = mutual.size() >= 9;
  const int n = static_cast<int>(use_mutual ? mutual.size() : forward.size());
  for (int k = 0; k < n; ++k) {
    const int i = use_mutual ? mutual[k] : k;
    s->push_back(source.cloud->points[i]);
    t->push_back(target.cloud->points[forward[i]]);
  }
}

// A pose and how well it lays one cloud on the other: the share of its points with a partner
// within the distance, and their RMS distance.
struct Fit {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  double fitness = 0;
  double inlier_rmse = 0;
};

// Open3D's EvaluateRegistration (the fitness and inlier RMSE of `source` moved by T against
// `target` within `distance`) with the target's nearest points found on a grid built once for
// every pose (nearest_point_grid.h): Open3D builds a k-d tree per call, 4-5 ms a candidate on
// the rendered rooms' 3500-point clouds.
Fit evaluateOn(const Cloud& source, const NearestPointGrid& target, const Eigen::Matrix4d& T) {
  Fit result;
  result.T = T;
  const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
  const Eigen::Vector3d t = T.topRightCorner<3, 1>();
  double error2 = 0;
  size_t within = 0;
  for (const Eigen::Vector3d& p : source.points) {
    double distance2 = 0;
    if (target.nearest(R * p + t, &distance2)) error2 += distance2, ++within;
  }
  if (within > 0) {
    result.fitness = static_cast<double>(within) / static_cast<double>(source.points.size());
    result.inlier_rmse = std::sqrt(error2 / static_cast<double>(within));
  }
  return result;
}

// Open3D's point-to-plane ICP, one of the plugin's steps.
Fit icp(const Open3dSteps& open3d, const Cloud& source, const Cloud& target, double distance,
        const Eigen::Matrix4d& initial, int iterations) {
  Fit f;
  open3d.icp(&source, &target, distance, &initial, iterations, &f.T, &f.fitness, &f.inlier_rmse);
  return f;
}

}  // namespace

bool registrationNeedsOpen3d(const DepthRegistrationOptions& o) {
  return o.method == GlobalRegistration::kOpen3dRansac || o.method == GlobalRegistration::kFast ||
         o.icp_iterations > 0 || o.covariance;
}

void registerDepthImagesHere(const cv::Mat& depth1, const cv::Mat& depth2,
                             const PinholeCamera& camera, double depth_scale,
                             const DepthRegistrationOptions& o, const Open3dSteps& open3d,
                             Depth1Description* described1, DepthRegistration* result) {
  DepthRegistration& r = *result;
  r = DepthRegistration{};
  const auto start = std::chrono::steady_clock::now();
  auto stage_start = start;
  auto lap = [&stage_start]() {
    const auto now = std::chrono::steady_clock::now();
    const double ms = std::chrono::duration<double, std::milli>(now - stage_start).count();
    stage_start = now;
    return ms;
  };
  auto finish = [&](const std::string& failure) {
    r.failure = failure;
    r.time_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  };
  // The two clouds are independent: each is built and described side by side on TBB's workers.
  // Depth 1's, where an earlier registration described it with the same camera and options, is
  // taken as it was; a new one is made in place, kept by the caller as it is used here (never
  // copied).
  std::shared_ptr<const DescribedDepth1> depth1_description =
      described1 != nullptr ? std::static_pointer_cast<const DescribedDepth1>(described1->given)
                            : nullptr;
  r.depth1_described_before = depth1_description != nullptr;
  const bool open3d_feature =
      o.method == GlobalRegistration::kOpen3dRansac || o.method == GlobalRegistration::kFast;
  std::shared_ptr<Cloud> full2;
  Prepared target;
  if (depth1_description != nullptr) {
    // Cloud 2 alone: its neighbour searches and descriptor sums take both cores
    // (grid_neighbours.cpp, fpfh.cpp).
    const double voxel = depth1_description->voxel;
    full2 = depthCloud(depth2, camera, depth_scale, o.pixel_stride, o.max_range_m);
    target = prepare(voxelDownSample(*full2, voxel), voxel, o.fpfh_neighbours, open3d_feature);
  } else {
    const auto made = std::make_shared<DescribedDepth1>();
    tbb::parallel_invoke(
        [&] {
          made->full = depthCloud(depth1, camera, depth_scale, o.pixel_stride, o.max_range_m);
          double voxel = registrationVoxel(*made->full, o);
          // Past max_points the voxel grows by the square root of the excess (the points lie on
          // surfaces): the descriptors' matching grows with the product of the two clouds'
          // sizes. The voxels are counted, not down-sampled: both clouds are down-sampled below,
          // side by side, at the voxel chosen here.
          if (o.max_points > 0) {
            const size_t occupied = occupiedVoxels(made->full->points, voxel);
            if (occupied > static_cast<size_t>(o.max_points)) {
              voxel *= std::sqrt(static_cast<double>(occupied) / o.max_points);
            }
          }
          made->voxel = voxel;
        },
        [&] { full2 = depthCloud(depth2, camera, depth_scale, o.pixel_stride, o.max_range_m); });
    const double voxel = made->voxel;
    tbb::parallel_invoke(
        [&] {
          made->prepared = prepare(voxelDownSample(*made->full, voxel), voxel, o.fpfh_neighbours,
                                   open3d_feature);
        },
        [&] {
          target =
              prepare(voxelDownSample(*full2, voxel), voxel, o.fpfh_neighbours, open3d_feature);
        });
    depth1_description = made;
    if (described1 != nullptr) described1->made = made;
  }
  const std::shared_ptr<Cloud>& full1 = depth1_description->full;
  const double voxel = depth1_description->voxel;
  const Prepared& source = depth1_description->prepared;
  r.voxel_m = voxel;
  r.prepare_ms = lap();
  r.points1 = static_cast<int>(source.cloud->points.size());
  r.points2 = static_cast<int>(target.cloud->points.size());
  constexpr int kMinPoints = 50;
  if (r.points1 < kMinPoints || r.points2 < kMinPoints) {
    return finish("too little depth for registration (" + std::to_string(r.points1) + " and " +
                  std::to_string(r.points2) + " points)");
  }

  const double match_distance = 1.5 * voxel;
  // Coarse poses: the search over the matches (the best pose, or every distinct well-supported
  // one), or Open3D's one.
  std::vector<Eigen::Matrix4d> coarse_poses;
  if (o.method == GlobalRegistration::kCandidates || o.method == GlobalRegistration::kRansac) {
    std::vector<Eigen::Vector3d> s, t;
    fpfhMatches(source, target, &s, &t);
    CorrespondenceRansacOptions search = o.candidates;
    search.inlier_distance_m = match_distance;
    search.seed = static_cast<unsigned>(o.seed);
    if (o.method == GlobalRegistration::kRansac) {
      // Open3D's search, its hypotheses scored the same way (the share of matches within the
      // inlier distance) without copying and moving the whole cloud for each, which made
      // Open3D's take 0.5-0.8 s on the rendered rooms.
      search.max_candidates = 1;
      search.max_iterations = o.ransac_iterations;
      search.confidence = o.ransac_confidence;
    }
    for (const RigidCandidate& c : ransacRigidPoses(s, t, search)) {
      coarse_poses.push_back(c.T_21.to_homogeneous_matrix());
    }
  } else {
    Eigen::Matrix4d coarse;
    if (open3d.global_search(source.cloud.get(), target.cloud.get(), &source.fpfh, &target.fpfh,
                             o.method == GlobalRegistration::kFast, match_distance,
                             o.ransac_iterations, o.ransac_confidence, o.seed, &coarse)) {
      coarse_poses.push_back(coarse);
    }
  }
  r.global_ms = lap();
  if (coarse_poses.empty()) return finish("registration found no overlap");

  // Point-to-plane ICP at the coarse voxel, then at the fine one (the coarse grid limits
  // accuracy to centimetres; the fine clouds are only built when RANSAC found something).
  // The fine stage runs only where it refines: on a voxel at least 2.5 times as fine (a room's
  // 10 cm voxel; not a cabinet's 6.5 cm one, where it cost 60-90 ms and gained no pose).
  const bool fine_stage =
      o.icp_iterations > 0 && o.fine_voxel_m > 0 && o.fine_voxel_m <= 0.4 * voxel + 1e-9;
  const auto fine1 =
      fine_stage ? std::make_shared<Cloud>(voxelDownSample(*full1, o.fine_voxel_m)) : source.cloud;
  const auto fine2 =
      fine_stage ? std::make_shared<Cloud>(voxelDownSample(*full2, o.fine_voxel_m)) : target.cloud;
  if (fine_stage) {
    estimateNormals(fine2.get(), 3.0 * o.fine_voxel_m, 30);
    orientNormalsTowardsCamera(fine2.get());
  }
  const double icp_distance = fine_stage ? 1.5 * o.fine_voxel_m : 0.8 * voxel;
  std::vector<Fit> refined;
  if (o.icp_iterations == 0) {
    // The caller refines (the depth path's RGB-D alignment); an unrefined pose's overlap is
    // measured at the distance the search scored it with, the candidates shared between two
    // threads (each pose's figures its own, whichever thread measures them).
    const NearestPointGrid target_grid(target.cloud->points, match_distance);
    refined.resize(coarse_poses.size());
    auto measure = [&](size_t begin, size_t step) {
      for (size_t k = begin; k < coarse_poses.size(); k += step) {
        refined[k] = evaluateOn(*source.cloud, target_grid, coarse_poses[k]);
      }
    };
    tbb::parallel_invoke([&] { measure(0, 2); }, [&] { measure(1, 2); });
  }
  for (const Eigen::Matrix4d& coarse : coarse_poses) {
    if (o.icp_iterations == 0) break;
    const Fit mid =
        icp(open3d, *source.cloud, *target.cloud, 0.8 * voxel, coarse, o.icp_iterations);
    refined.push_back(
        fine_stage ? icp(open3d, *fine1, *fine2, icp_distance, mid.T, o.icp_iterations) : mid);
  }
  const Fit& fine = refined.front();
  r.icp_ms = lap();
  const Eigen::Matrix4d T = fine.T;
  if (!T.allFinite()) return finish("registration diverged");
  r.T_21 = SE3Quat(T.topLeftCorner<3, 3>(), T.topRightCorner<3, 1>());
  // Candidates that ICP brought to one pose are one candidate (the better-supported first).
  for (const Fit& c : refined) {
    const Eigen::Matrix4d& Tc = c.T;
    if (!Tc.allFinite()) continue;
    const SE3Quat pose(Tc.topLeftCorner<3, 3>(), Tc.topRightCorner<3, 1>());
    const bool repeated = std::any_of(r.candidates.begin(), r.candidates.end(), [&](const auto& k) {
      const SE3Quat d = k.T_21.inverse() * pose;
      return d.log().head<3>().norm() * 180.0 / M_PI <= o.candidates.distinct_deg &&
             d.translation().norm() <= std::max(2.0 * voxel, 0.05);
    });
    if (!repeated) r.candidates.push_back({pose, c.fitness});
  }
  r.fitness = fine.fitness;
  r.inlier_rmse = fine.inlier_rmse;

  // Open3D's information matrix is J^T J of point-to-point residuals over the correspondences,
  // in (rotation, translation) order for a left perturbation: ours. Scaled by the residual
  // variance it would be the inverse covariance if the residuals were independent; they are
  // not (voxel grids, smooth depth noise, surfaces seen partly), and on rendered rooms the
  // true error was 17-23x that 1-sigma. kSigmaInflation makes the reported 1-sigma honest.
  if (o.covariance) {
    Eigen::Matrix<double, 6, 6> info;
    open3d.information(fine1.get(), fine2.get(), icp_distance, &T, &info);
    constexpr double kSigmaInflation = 20.0;
    const double sigma2 =
        kSigmaInflation * kSigmaInflation * std::max(r.inlier_rmse * r.inlier_rmse, 1e-6);
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eig(info);
    if (eig.eigenvalues()(0) > 1e-9 * std::max(eig.eigenvalues()(5), 1e-300)) {
      r.covariance = sigma2 * info.inverse();
      r.covariance_ok = r.covariance.allFinite();
    }
  }
  r.ok = true;
  finish("");
}

}  // namespace pnpba
