// pcl_registration_probe: the depth-only registration done with PCL instead of Open3D, on the
// same rendered closed-room pairs as wide_baseline_bench, with the same recipe (10 cm voxels,
// normals at 2 voxels, FPFH at 5 voxels, RANSAC on FPFH matches, point-to-plane ICP at the coarse
// then a 4 cm voxel), side by side with pnpba's Open3D path (registerDepthImages). Counts poses
// within 2 deg / 5 cm of the truth and the median time. Built only with -DPNPBA_BUILD_PCL_PROBE=ON
// (needs libpcl-dev); it measured the choice of registration library (docs/two_view.md).
//
//   build/bench/pcl_registration_probe [--seeds 2]
#include <pcl/common/transforms.h>
#include <pcl/features/fpfh.h>
#include <pcl/features/normal_3d.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl/point_types.h>
#include <pcl/registration/icp.h>
#include <pcl/registration/sample_consensus_prerejective.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "guarded_main.h"
#include "pnpba/evaluation/evaluation.h"
#include "pnpba/pipeline/depth_registration.h"
#include "pnpba/synthetic/synthetic_pair.h"
#include "pnpba/synthetic/synthetic_scene.h"
#include "wide_baseline_pairs.h"

namespace {

using Cloud = pcl::PointCloud<pcl::PointNormal>;
using Features = pcl::PointCloud<pcl::FPFHSignature33>;

Cloud::Ptr depthCloud(const cv::Mat& depth, const pnpba::PinholeCamera& c, double scale) {
  auto cloud = pcl::make_shared<Cloud>();
  for (int v = 0; v < depth.rows; v += 4) {
    for (int u = 0; u < depth.cols; u += 4) {
      const double z = depth.at<uint16_t>(v, u) / scale;
      if (z <= 0.1 || z > 6.0) continue;
      pcl::PointNormal p;
      p.x = static_cast<float>((u - c.cx) / c.fx * z);
      p.y = static_cast<float>((v - c.cy) / c.fy * z);
      p.z = static_cast<float>(z);
      cloud->push_back(p);
    }
  }
  return cloud;
}

Cloud::Ptr downsampleWithNormals(const Cloud::Ptr& in, float voxel) {
  auto out = pcl::make_shared<Cloud>();
  pcl::VoxelGrid<pcl::PointNormal> grid;
  grid.setLeafSize(voxel, voxel, voxel);
  grid.setInputCloud(in);
  grid.filter(*out);
  pcl::NormalEstimation<pcl::PointNormal, pcl::PointNormal> normals;
  normals.setRadiusSearch(2 * voxel);
  normals.setInputCloud(out);
  normals.compute(*out);
  return out;
}

Features::Ptr fpfh(const Cloud::Ptr& cloud, float voxel) {
  auto f = pcl::make_shared<Features>();
  pcl::FPFHEstimation<pcl::PointNormal, pcl::PointNormal, pcl::FPFHSignature33> est;
  est.setRadiusSearch(5 * voxel);
  est.setInputCloud(cloud);
  est.setInputNormals(cloud);
  est.compute(*f);
  return f;
}

bool registerWithPcl(const cv::Mat& d1, const cv::Mat& d2, const pnpba::PinholeCamera& c,
                     double scale, Eigen::Matrix4f* T) {
  const float voxel = 0.1f, fine = 0.04f;
  const Cloud::Ptr full1 = depthCloud(d1, c, scale), full2 = depthCloud(d2, c, scale);
  const Cloud::Ptr s = downsampleWithNormals(full1, voxel), t = downsampleWithNormals(full2, voxel);
  if (s->size() < 50 || t->size() < 50) return false;
  pcl::SampleConsensusPrerejective<pcl::PointNormal, pcl::PointNormal, pcl::FPFHSignature33> ransac;
  ransac.setInputSource(s);
  ransac.setSourceFeatures(fpfh(s, voxel));
  ransac.setInputTarget(t);
  ransac.setTargetFeatures(fpfh(t, voxel));
  ransac.setMaximumIterations(100000);
  ransac.setNumberOfSamples(3);
  ransac.setCorrespondenceRandomness(1);
  ransac.setSimilarityThreshold(0.9f);
  ransac.setMaxCorrespondenceDistance(1.5f * voxel);
  ransac.setInlierFraction(0.05f);
  Cloud aligned;
  ransac.align(aligned);
  if (!ransac.hasConverged()) return false;
  Eigen::Matrix4f guess = ransac.getFinalTransformation();
  for (const auto& [cloud_voxel, distance] :
       {std::pair<float, float>{voxel, 0.8f * voxel}, {fine, 1.5f * fine}}) {
    const Cloud::Ptr a = cloud_voxel == voxel ? s : downsampleWithNormals(full1, cloud_voxel);
    const Cloud::Ptr b = cloud_voxel == voxel ? t : downsampleWithNormals(full2, cloud_voxel);
    pcl::IterativeClosestPointWithNormals<pcl::PointNormal, pcl::PointNormal> icp;
    icp.setInputSource(a);
    icp.setInputTarget(b);
    icp.setMaxCorrespondenceDistance(distance);
    icp.setMaximumIterations(30);
    icp.align(aligned, guess);
    guess = icp.getFinalTransformation();
  }
  *T = guess;
  return true;
}

}  // namespace

// The bench itself (main: guarded_main.h).
static int benchMain(int argc, char** argv) {
  const int seeds = argc > 2 && std::string(argv[1]) == "--seeds" ? std::atoi(argv[2]) : 2;
  int ok_pcl = 0, ok_o3d = 0, pairs = 0;
  std::vector<double> t_pcl, t_o3d;
  for (double deg : {10.0, 30.0, 45.0}) {
    for (double metres : {0.25, 1.0}) {
      for (int s = 0; s < seeds; ++s) {
        const pnpba::SyntheticPairOptions o =
            pnpba::bench::wideBaselinePair(pnpba::bench::SweepScene::kPoor, deg, metres, s);
        const pnpba::SyntheticPair p = pnpba::renderSyntheticPair(o);
        const pnpba::PinholeCamera cam = o.camera.pinhole;
        const double scale = o.camera.depth_scale;
        ++pairs;
        auto start = std::chrono::steady_clock::now();
        Eigen::Matrix4f T;
        const bool got = registerWithPcl(p.view1.depth, p.view2.depth, cam, scale, &T);
        t_pcl.push_back(
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count());
        double pcl_deg = -1, pcl_cm = -1;
        if (got) {
          const Eigen::Matrix4d Td = T.cast<double>();
          const pnpba::PoseError e = pnpba::relativePoseError(
              pnpba::SE3Quat(Td.topLeftCorner<3, 3>(), Td.topRightCorner<3, 1>()), p.T_21);
          pcl_deg = e.rot_deg, pcl_cm = e.trans_cm;
          ok_pcl += e.rot_deg <= 2 && e.trans_cm <= 5;
        }
        const pnpba::DepthRegistration r = pnpba::registerDepthImages(
            p.view1.depth, p.view2.depth, cam, scale, pnpba::DepthRegistrationOptions{});
        t_o3d.push_back(r.time_ms);
        double o3d_deg = -1, o3d_cm = -1;
        if (r.ok) {
          const pnpba::PoseError e = pnpba::relativePoseError(r.T_21, p.T_21);
          o3d_deg = e.rot_deg, o3d_cm = e.trans_cm;
          ok_o3d += e.rot_deg <= 2 && e.trans_cm <= 5;
        }
        std::printf(
            "%4.0f deg %4.2f m seed %d: PCL %6.2f deg %6.1f cm %7.0f ms | Open3D %6.2f deg "
            "%6.1f cm %7.0f ms\n",
            deg, metres, s, pcl_deg, pcl_cm, t_pcl.back(), o3d_deg, o3d_cm, r.time_ms);
      }
    }
  }
  auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  std::printf(
      "poor-texture room, %d pairs: PCL %d ok, median %.0f ms; Open3D %d ok, median %.0f ms\n",
      pairs, ok_pcl, median(t_pcl), ok_o3d, median(t_o3d));
  return 0;
}

int main(int argc, char** argv) {
  return pnpba::bench::guardedMain("pcl_registration_probe", benchMain, argc, argv);
}
