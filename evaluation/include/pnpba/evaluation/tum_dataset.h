// TUM RGB-D benchmark sequences: frame lists, association of colour and depth by time stamp,
// and ground truth interpolated at an image's stamp.
//
// Files (TUM conventions): `rgb.txt` / `depth.txt` ("stamp path" lines), `associate.txt`
// ("t_rgb rgb/... t_depth depth/..."), `groundtruth.txt` ("stamp tx ty tz qx qy qz qw",
// camera-to-world). '#' starts a comment line.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "pnpba/optimize/se3_quat.h"

namespace pnpba {

struct TumFrame {
  double rgb_stamp = 0;
  std::string rgb;  // path relative to the sequence folder
  double depth_stamp = 0;
  std::string depth;
};

struct StampedPose {
  double stamp = 0;
  SE3Quat T_wc;  // camera to world
};

// "stamp path" lines. Throws Error "<path>:<line>: <problem>".
std::vector<std::pair<double, std::string>> readStampedList(const std::string& path);
// associate.txt. Throws Error "<path>:<line>: <problem>".
std::vector<TumFrame> readAssociations(const std::string& path);
// Each colour frame paired with the depth frame nearest in time, if within max_difference
// seconds and not already taken by a nearer colour frame (the TUM associate.py rule).
std::vector<TumFrame> associate(const std::vector<std::pair<double, std::string>>& rgb,
                                const std::vector<std::pair<double, std::string>>& depth,
                                double max_difference = 0.02);
// groundtruth.txt, sorted by stamp. Throws Error "<path>:<line>: <problem>".
std::vector<StampedPose> readTrajectory(const std::string& path);

// Ground truth at `stamp`: linear in translation, slerp in rotation between the two
// neighbouring samples. Nothing when the stamp is outside the trajectory or the neighbours are
// more than max_gap seconds apart.
std::optional<SE3Quat> interpolatePose(const std::vector<StampedPose>& trajectory, double stamp,
                                       double max_gap = 0.1);

struct TumSequence {
  std::string folder;
  std::vector<TumFrame> frames;                      // frames whose files exist, in time order
  std::vector<std::optional<SE3Quat>> ground_truth;  // per frame (T_wc), if available
  int frames_without_ground_truth = 0;
  int frames_missing_files = 0;
};

// A key-frame folder's poses.txt: "frame stamp tx ty tz qx qy qz qw" per line (camera to
// world); frame NNNN is rgb/NNNN.jpg (or .png) + depth/NNNN.png. Frames whose files are missing
// are counted, not listed. Throws Error "<path>:<line>: <problem>".
struct KeyFrames {
  std::vector<TumFrame> frames;  // stamps from poses.txt, in file order
  std::vector<SE3Quat> poses;    // T_wc per frame
  int missing_files = 0;
};
KeyFrames readKeyFrames(const std::string& folder);

// Reads a sequence folder: associate.txt if present, else rgb.txt + depth.txt associated
// within 0.02 s; groundtruth.txt interpolated at each colour stamp + gt_offset seconds.
// A key-frame folder (poses.txt, no rgb.txt or associate.txt) gives its frames and their poses
// as they are (gt_offset does not apply: each pose belongs to its frame).
TumSequence loadTumSequence(const std::string& folder, double gt_offset = 0.0);

// Writes a TUM trajectory ("stamp tx ty tz qx qy qz qw" per line, camera-to-world).
std::string formatTumPose(double stamp, const SE3Quat& T_wc);

}  // namespace pnpba
