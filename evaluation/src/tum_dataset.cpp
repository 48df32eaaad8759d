#include "pnpba/evaluation/tum_dataset.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "pnpba/core/error.h"
#include "pnpba/core/parse_number.h"

namespace pnpba {

namespace {

// Calls parse(fields, where) for each non-comment, non-blank line.
template <typename Parse>
void forEachLine(const std::string& path, Parse parse) {
  std::ifstream in(path);
  if (!in) throw Error(path + ": cannot open file");
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const auto first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream fields(line);
    std::vector<std::string> tokens;
    for (std::string t; fields >> t;) tokens.push_back(t);
    parse(tokens, path + ":" + std::to_string(line_no) + ": ");
  }
}

double number(const std::string& token, const std::string& where) {
  return numberOrThrow(token, where);
}

}  // namespace

std::vector<std::pair<double, std::string>> readStampedList(const std::string& path) {
  std::vector<std::pair<double, std::string>> out;
  forEachLine(path, [&](const std::vector<std::string>& t, const std::string& where) {
    if (t.size() != 2) throw Error(where + "expected 'stamp path'");
    out.emplace_back(number(t[0], where), t[1]);
  });
  return out;
}

std::vector<TumFrame> readAssociations(const std::string& path) {
  std::vector<TumFrame> out;
  forEachLine(path, [&](const std::vector<std::string>& t, const std::string& where) {
    if (t.size() != 4) throw Error(where + "expected 't_rgb rgb_path t_depth depth_path'");
    out.push_back({number(t[0], where), t[1], number(t[2], where), t[3]});
  });
  return out;
}

std::vector<TumFrame> associate(const std::vector<std::pair<double, std::string>>& rgb,
                                const std::vector<std::pair<double, std::string>>& depth,
                                double max_difference) {
  // All candidate pairs within the limit, closest first; each stamp used once.
  struct Candidate {
    double dt;
    size_t r, d;
  };
  std::vector<Candidate> candidates;
  for (size_t r = 0; r < rgb.size(); ++r) {
    for (size_t d = 0; d < depth.size(); ++d) {
      const double dt = std::abs(rgb[r].first - depth[d].first);
      if (dt < max_difference) candidates.push_back({dt, r, d});
    }
  }
  std::sort(candidates.begin(), candidates.end(),
            [](const Candidate& a, const Candidate& b) { return a.dt < b.dt; });
  std::vector<char> rgb_used(rgb.size(), 0), depth_used(depth.size(), 0);
  std::vector<TumFrame> out;
  for (const Candidate& c : candidates) {
    if (rgb_used[c.r] || depth_used[c.d]) continue;
    rgb_used[c.r] = depth_used[c.d] = 1;
    out.push_back({rgb[c.r].first, rgb[c.r].second, depth[c.d].first, depth[c.d].second});
  }
  std::sort(out.begin(), out.end(),
            [](const TumFrame& a, const TumFrame& b) { return a.rgb_stamp < b.rgb_stamp; });
  return out;
}

std::vector<StampedPose> readTrajectory(const std::string& path) {
  std::vector<StampedPose> out;
  forEachLine(path, [&](const std::vector<std::string>& t, const std::string& where) {
    if (t.size() != 8) throw Error(where + "expected 'stamp tx ty tz qx qy qz qw'");
    double v[8];
    for (int i = 0; i < 8; ++i) v[i] = number(t[i], where);
    const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
    if (!(q.norm() > 0.5)) throw Error(where + "quaternion is not unit length");
    out.push_back({v[0], SE3Quat(q.normalized(), Eigen::Vector3d(v[1], v[2], v[3]))});
  });
  std::sort(out.begin(), out.end(),
            [](const StampedPose& a, const StampedPose& b) { return a.stamp < b.stamp; });
  return out;
}

std::optional<SE3Quat> interpolatePose(const std::vector<StampedPose>& trajectory, double stamp,
                                       double max_gap) {
  auto after = std::lower_bound(trajectory.begin(), trajectory.end(), stamp,
                                [](const StampedPose& p, double s) { return p.stamp < s; });
  if (after == trajectory.end()) return std::nullopt;
  if (after->stamp == stamp) return after->T_wc;
  if (after == trajectory.begin()) return std::nullopt;
  const auto before = after - 1;
  const double gap = after->stamp - before->stamp;
  if (gap > max_gap) return std::nullopt;
  const double a = (stamp - before->stamp) / gap;
  const Eigen::Vector3d t = (1 - a) * before->T_wc.translation() + a * after->T_wc.translation();
  const Eigen::Quaterniond q = before->T_wc.rotation().slerp(a, after->T_wc.rotation());
  return SE3Quat(q, t);
}

KeyFrames readKeyFrames(const std::string& folder) {
  namespace fs = std::filesystem;
  KeyFrames out;
  forEachLine(folder + "/poses.txt",
              [&](const std::vector<std::string>& t, const std::string& where) {
                if (t.size() != 9)
                  throw Error(where + "expected 'frame stamp tx ty tz qx qy qz qw'");
                double v[8];
                for (int i = 0; i < 8; ++i) v[i] = number(t[i + 1], where);
                const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
                if (!(q.norm() > 0.5)) throw Error(where + "quaternion is not unit length");
                TumFrame f{v[0], "rgb/" + t[0] + ".jpg", v[0], "depth/" + t[0] + ".png"};
                if (!fs::exists(folder + "/" + f.rgb)) f.rgb = "rgb/" + t[0] + ".png";
                if (!fs::exists(folder + "/" + f.rgb) || !fs::exists(folder + "/" + f.depth)) {
                  ++out.missing_files;
                  return;
                }
                out.frames.push_back(f);
                out.poses.push_back(SE3Quat(q.normalized(), Eigen::Vector3d(v[1], v[2], v[3])));
              });
  return out;
}

TumSequence loadTumSequence(const std::string& folder, double gt_offset) {
  namespace fs = std::filesystem;
  if (!fs::is_directory(folder)) throw Error(folder + ": not a folder");
  TumSequence seq;
  seq.folder = folder;
  if (fs::exists(folder + "/poses.txt") && !fs::exists(folder + "/associate.txt") &&
      !fs::exists(folder + "/rgb.txt")) {
    KeyFrames k = readKeyFrames(folder);
    seq.frames = std::move(k.frames);
    seq.ground_truth.assign(k.poses.begin(), k.poses.end());
    seq.frames_missing_files = k.missing_files;
    return seq;
  }
  std::vector<TumFrame> frames;
  if (fs::exists(folder + "/associate.txt")) {
    frames = readAssociations(folder + "/associate.txt");
  } else {
    frames =
        associate(readStampedList(folder + "/rgb.txt"), readStampedList(folder + "/depth.txt"));
  }
  for (const TumFrame& f : frames) {
    if (fs::exists(folder + "/" + f.rgb) && fs::exists(folder + "/" + f.depth)) {
      seq.frames.push_back(f);
    } else {
      ++seq.frames_missing_files;
    }
  }
  std::sort(seq.frames.begin(), seq.frames.end(),
            [](const TumFrame& a, const TumFrame& b) { return a.rgb_stamp < b.rgb_stamp; });
  std::vector<StampedPose> trajectory;
  if (fs::exists(folder + "/groundtruth.txt"))
    trajectory = readTrajectory(folder + "/groundtruth.txt");
  for (const TumFrame& f : seq.frames) {
    seq.ground_truth.push_back(interpolatePose(trajectory, f.rgb_stamp + gt_offset));
    if (!seq.ground_truth.back()) ++seq.frames_without_ground_truth;
  }
  return seq;
}

std::string formatTumPose(double stamp, const SE3Quat& T_wc) {
  const Eigen::Vector3d& t = T_wc.translation();
  const Eigen::Quaterniond& q = T_wc.rotation();
  char line[256];
  std::snprintf(line, sizeof line, "%.6f %.6f %.6f %.6f %.6f %.6f %.6f %.6f", stamp, t.x(), t.y(),
                t.z(), q.x(), q.y(), q.z(), q.w());
  return line;
}

}  // namespace pnpba
