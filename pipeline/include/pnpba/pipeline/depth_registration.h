// The depth-only path of the two-view pose: global registration of the two depth images as
// point clouds (voxel down-sampling, normals, FPFH descriptors, a search over descriptor
// matches, optionally point-to-plane ICP), for scenes whose texture is too poor for features.
// The default steps are pnpba's own and open no plugin; Open3D's own steps (its RANSAC or fast
// global registration, ICP, the information-matrix covariance) come from a plugin opened the
// first time an option asks for one of them. Nothing of Open3D is public.
//
// The search is a RANSAC over mutual FPFH matches whose hypotheses are scored on the matches
// themselves (correspondence_ransac.h), each pose refined on its inlier matches, with no ICP;
// the depth path's RGB-D alignment refines it. The default (kCandidates) returns every distinct
// pose with support, up to 8: in a scene of a few planes the truth is often a rival, not the
// best-supported pose, and the depth path screens the rivals and aligns the ones the depths
// support most (TwoViewOptions::aligned_registration_candidates). kRansac returns the best pose
// alone (the default until 2026-11-27); it finds what Open3D's RANSAC (kOpen3dRansac, kept for
// comparison) finds, 6-7x faster on the rendered rooms: Open3D copies and moves the whole cloud
// for every hypothesis. docs/two_view.md has the measurements.
//
// T_21 maps camera-1 points onto camera-2 points (DESIGN.md section 3). Deterministic: every
// search is seeded and independent of the thread count, so the same depths give the same pose
// on every run.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "pnpba/features/pinhole_camera.h"
#include "pnpba/optimize/se3_quat.h"
#include "pnpba/pipeline/correspondence_ransac.h"

namespace pnpba {

class LaterFeatures;  // frame_features.h

// How the coarse pose is found from the FPFH descriptor matches.
enum class GlobalRegistration {
  // RANSAC over matched triples scored on the matches (correspondence_ransac.h), the best pose
  kRansac,
  kOpen3dRansac,  // the same search by Open3D's RegistrationRANSACBasedOnFeatureMatching
  kFast,          // Fast Global Registration: a graduated non-convex fit to all matches at once
  // RANSAC over matched triples scored on the matches themselves, returning every distinct
  // well-supported pose (correspondence_ransac.h) for the depth path's evidence to choose from
  kCandidates,
};
const char* toString(GlobalRegistration method);
GlobalRegistration parseGlobalRegistration(const std::string& name);  // throws Error

struct DepthRegistrationOptions {
  // Open3D's RANSAC (with ICP) took 1-2 s a pair on the rendered 9 m room; the default search
  // 80-110 ms, and the descriptors 120-180 ms (docs/benchmarks.md).
  GlobalRegistration method = GlobalRegistration::kCandidates;
  // RANSAC's voxel; normals at 2x, FPFH at 5x this radius. On the rendered sweep 12 cm was
  // 20-35 % faster with no wrong pose, 14 cm gave one: 10 cm keeps a margin (docs/two_view.md).
  double voxel_m = 0.1;
  // An FPFH descriptor sums the histograms of at most this many neighbours (within its radius):
  // most of the descriptors' time (145-190 ms a cloud in the rendered room), which is most of
  // the registration's. 50 on the rendered sweep: the cabinet scene 56 right and 1 wrong
  // against 58 and none.
  int fpfh_neighbours = 100;
  // When > 0, the voxel is this fraction of depth 1's median when that is smaller than voxel_m:
  // close scenes get a finer grid (fr3_cabinet at 1.3 m: 6.5 cm, 44 of 54 pairs right against
  // 40 at 10 cm).
  double voxel_depth_fraction = 0.05;
  // Cloud 1 keeps about this many points at most (0: no limit): past it the voxel grows by the
  // square root of the excess. The descriptors' matching grows with the product of the two
  // clouds' sizes, so the cap bounds the registration's time whatever the camera or the scene:
  // through a 93-degree 1280 x 720 camera the room gave 11 000-12 000 points and 50-60 ms of
  // matching instead of 15. The rendered room through a TUM camera holds 3700-5800 points at
  // 10 cm; over the 3-seed sweep the poor room's p95 read 147 ms at 6000, 132 at 4500 and 111
  // at 3500, with the rich and poor counts the same and the cabinet's 49 -> 51 right. Below
  // 3500 the counts start to move (2500: poor 80 right instead of 81). fr1_desk, fr3_cabinet
  // and cabinet-wide stay below it (docs/benchmarks.md, "The registration's point cap").
  int max_points = 3500;
  // With icp_iterations > 0, a last point-to-plane ICP on this finer voxel, where it is at most
  // 0.4 of the voxel (0: none). Measured with Open3D's RANSAC on the rendered cabinet scene (108
  // pairs, 10 cm voxels, before the RGB-D alignment refined): without it 44 right and 2 wrong,
  // with it 51 and none.
  double fine_voxel_m = 0.04;
  double max_range_m = 6.0;  // farther depth is dropped (noise grows as z^2)
  // Back-project every n-th pixel before down-sampling. 8 halved the time and let one wrong
  // pose through on the rendered cabinet scene (a 3 m slide along the wall). This is the stride
  // at 640 x 480; a larger image's grows with its side (7 at 1280 x 720), so as to back-project
  // about as many points.
  int pixel_stride = 4;
  // kRansac, kOpen3dRansac: at most; the search stops earlier at `ransac_confidence`. With
  // Open3D's RANSAC, 10 000 instead of 100 000 lost 8 of the rendered cabinet's 51 right poses
  // and let one wrong one through.
  int ransac_iterations = 100000;
  double ransac_confidence = 0.999;
  // Point-to-plane ICP iterations per stage after the search; 0 (default): none, the poses are
  // returned as the search found them, refined on their inlier matches, and the depth path's
  // RGB-D alignment refines each. ICP there cost 170-230 ms a pair on the rendered rooms and
  // gained nothing the alignment does not (kCandidates: it left 6 of the sweep's cabinet poses
  // 6-13 cm off where without it none were; docs/benchmarks.md has the kRansac figures).
  int icp_iterations = 0;
  // The search over matches (kCandidates; kRansac takes its edge check and threads, with one
  // candidate, ransac_iterations and ransac_confidence). Its inlier distance is set to 1.5
  // voxels, its seed to `seed`. Up to 8 distinct poses: in a scene of a few planes the truth is
  // often not the best-supported one (fr3_cabinet key frames five and eight apart: within
  // 5 deg / 25 cm of the truth 6 of 45 best poses, 14 of 45 among three, 18 among eight); the
  // depth path screens them (TwoViewOptions::aligned_registration_candidates).
  CorrespondenceRansacOptions candidates = [] {
    CorrespondenceRansacOptions c;
    c.max_candidates = 8;
    return c;
  }();
  int seed = 42;
  // Fill DepthRegistration::covariance (Open3D's information matrix of the returned pose, which
  // builds a k-d tree of cloud 2: 3 ms of a rendered room's 42, and opens Open3D's plugin). The
  // depth path measures its pose's covariance from the RGB-D alignment instead and turns this
  // off.
  bool covariance = true;
  std::string validate() const;  // empty when valid
};

struct DepthRegistration {
  bool ok = false;
  std::string failure;  // when !ok: "too few depth points", "registration found no overlap"
  SE3Quat T_21;
  // Every distinct pose the search found support for, best first (the first is T_21 with its
  // fitness): the depth path aligns each and lets the evidence choose, or refuses when it cannot.
  struct Candidate {
    SE3Quat T_21;
    double fitness = 0;
  };
  std::vector<Candidate> candidates;
  // Fraction of cloud-1 points with a cloud-2 point within the last ICP's distance, or within
  // 1.5 voxels (the search's inlier distance) for an unrefined pose.
  double fitness = 0;
  double inlier_rmse = 0;        // m, over those points
  int points1 = 0, points2 = 0;  // after down-sampling
  // Covariance of T_21 in [w, v] order (left perturbation) for the point-to-plane residuals at
  // their measured RMSE; covariance_ok is false when the geometry leaves a direction free.
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
  bool covariance_ok = false;
  double voxel_m = 0;  // the voxel used
  // Depth 1's cloud and descriptors were taken from an earlier registration (depth1_kept below)
  // rather than made: the same registration, in less time.
  bool depth1_described_before = false;
  double time_ms = 0;
  double prepare_ms = 0;  // clouds, normals and descriptors
  double global_ms = 0;   // the coarse pose from descriptor matches
  double icp_ms = 0;      // the two point-to-plane ICP stages
  // What this call spent opening Open3D's plugin before it could start: a process's first
  // registration whose options take one of Open3D's steps (preloadDepthRegistration() takes it
  // out of every call), else 0; time_ms above is the registration's own work.
  double plugin_load_ms = 0;
};

// Throws Error for invalid options or depths that are not CV_16UC1; returns ok = false when
// there is too little depth or no registration was found. depth1_kept, where given, is depth 1's
// frame's store (frame_features.h): depth 1's description (its cloud, voxel, normals and
// descriptors: half the preparation's work) is taken from it where an earlier registration of
// the same depth pixels with the same camera and options kept it there, else made and kept
// there; the registration is the same either way.
DepthRegistration registerDepthImages(const cv::Mat& depth1, const cv::Mat& depth2,
                                      const PinholeCamera& camera, double depth_scale,
                                      const DepthRegistrationOptions& options,
                                      LaterFeatures* depth1_kept = nullptr);

// Opens the registration's Open3D plugin (about 100 shared libraries, 25-90 ms once per
// process) now rather than in the first registration whose options take one of Open3D's steps
// (the two-view pose's depth path takes none), for a loop that wants every pair's time to be
// its own. Returns the milliseconds it took (0 when already open); throws Error as
// that first pair would (the plugin missing, or of another build).
double preloadDepthRegistration();

}  // namespace pnpba
