// The functions the Open3D plugin (pipeline/plugin/open3d_steps.cpp) exports and the depth-only
// registration (registration/registration.cpp) calls: the registration's steps that are Open3D's
// own, taken only where its options ask for them (DepthRegistrationOptions: the global search
// open3d-ransac or fast, ICP iterations, the covariance). The registration's default steps are
// pnpba's and open no plugin: opening Open3D takes 50-90 ms, more than the whole registration.
// Both sides are built together (the plugin's ABI tag says so) and pass pnpba's own types by
// pointer; no function throws.
#pragma once

#include <Eigen/Core>

#include "registration/cloud.h"

namespace pnpba {

inline constexpr const char* kOpen3dPlugin = "open3d";

using FpfhRows = Eigen::Matrix<double, 33, Eigen::Dynamic>;

// The coarse pose of `source` onto `target` (down-sampled, with normals) from their FPFH
// descriptors: Open3D's RANSAC on mutual matches (fast = false) or its fast global registration
// (fast = true), seeded with `seed`. False where it found fewer than 3 correspondences or failed.
using Open3dGlobalSearch = bool(const Cloud* source, const Cloud* target,
                                const FpfhRows* source_fpfh, const FpfhRows* target_fpfh, bool fast,
                                double match_distance, int iterations, double confidence, int seed,
                                Eigen::Matrix4d* T);

// Open3D's point-to-plane ICP of `source` onto `target` (which has normals) from `initial`,
// pairs within `distance`: the pose, its fitness and inlier RMSE.
using Open3dIcp = void(const Cloud* source, const Cloud* target, double distance,
                       const Eigen::Matrix4d* initial, int iterations, Eigen::Matrix4d* T,
                       double* fitness, double* inlier_rmse);

// Open3D's information matrix of the pose T from the clouds' correspondences within `distance`
// (J^T J of point-to-point residuals, rotation then translation, a left perturbation).
using Open3dInformation = void(const Cloud* source, const Cloud* target, double distance,
                               const Eigen::Matrix4d* T, Eigen::Matrix<double, 6, 6>* information);

// The three together, as the registration is handed them (null where its options need none).
struct Open3dSteps {
  Open3dGlobalSearch* global_search = nullptr;
  Open3dIcp* icp = nullptr;
  Open3dInformation* information = nullptr;
};

}  // namespace pnpba
