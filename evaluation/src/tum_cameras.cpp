#include "pnpba/evaluation/tum_cameras.h"

#include <cctype>
#include <filesystem>

#include "pnpba/core/error.h"

namespace pnpba {

Camera tumFreiburgCamera(int freiburg) {
  // https://cvg.cit.tum.de/data/datasets/rgbd-dataset/file_formats ("Intrinsic Camera
  // Calibration of the Kinect"): fx fy cx cy d0..d4.
  Camera c;
  c.depth_scale = 5000.0;
  c.width = 640, c.height = 480;
  switch (freiburg) {
    case 1:
      c.pinhole.fx = 517.3, c.pinhole.fy = 516.5, c.pinhole.cx = 318.6, c.pinhole.cy = 255.3;
      c.pinhole.distortion = {0.2624, -0.9531, -0.0054, 0.0026, 1.1633};
      return c;
    case 2:
      c.pinhole.fx = 520.9, c.pinhole.fy = 521.0, c.pinhole.cx = 325.1, c.pinhole.cy = 249.7;
      c.pinhole.distortion = {0.2312, -0.7849, -0.0033, -0.0001, 0.9172};
      return c;
    case 3:
      c.pinhole.fx = 535.4, c.pinhole.fy = 539.2, c.pinhole.cx = 320.1, c.pinhole.cy = 247.6;
      return c;
  }
  throw Error("TUM RGB-D has freiburg cameras 1, 2 and 3, not " + std::to_string(freiburg));
}

Camera tumFreiburg1Camera() { return tumFreiburgCamera(1); }

namespace {

// The freiburg cameras one path component names as words: "freiburgN" or "frN", N in 1..3,
// with no letter or digit on either side. A bit per camera.
unsigned camerasNamedBy(const std::string& component) {
  std::string s;
  for (char ch : component) s += static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  const auto word_edge = [&s](size_t i) {
    return i >= s.size() || !std::isalnum(static_cast<unsigned char>(s[i]));
  };
  unsigned named = 0;
  for (const std::string prefix : {"freiburg", "fr"}) {
    for (size_t at = s.find(prefix); at != std::string::npos; at = s.find(prefix, at + 1)) {
      const size_t digit = at + prefix.size();
      if ((at > 0 && !word_edge(at - 1)) || digit >= s.size()) continue;
      if (s[digit] < '1' || s[digit] > '3' || !word_edge(digit + 1)) continue;
      named |= 1u << (s[digit] - '1');
    }
  }
  return named;
}

}  // namespace

int tumFreiburgNamedBy(const std::string& folder) {
  std::error_code ec;
  std::filesystem::path path = std::filesystem::absolute(folder, ec);
  if (ec) path = folder;
  path = path.lexically_normal();
  // Innermost first: a sequence's own name outranks the folder it was unpacked in.
  for (std::filesystem::path p = path; !p.empty() && p != p.root_path(); p = p.parent_path()) {
    const unsigned named = camerasNamedBy(p.filename().string());
    if (named == 0) continue;
    if ((named & (named - 1)) != 0) return 0;  // two cameras in one name: not a guess to make
    return named == 1u ? 1 : named == 2u ? 2 : 3;
  }
  return 0;
}

SequenceCamera sequenceCamera(const std::string& folder, const std::string& camera_path) {
  SequenceCamera out;
  if (!camera_path.empty()) {
    out.camera = loadCameraYaml(camera_path);
    out.source = camera_path;
    return out;
  }
  const std::string own = (std::filesystem::path(folder) / "camera.yaml").string();
  if (std::filesystem::exists(own)) {
    out.camera = loadCameraYaml(own);
    out.source = own;
    return out;
  }
  if (const int named = tumFreiburgNamedBy(folder); named != 0) {
    out.camera = tumFreiburgCamera(named);
    out.freiburg = named;
    out.source = "TUM freiburg" + std::to_string(named) + " (named by the folder)";
    return out;
  }
  out.camera = tumFreiburgCamera(1);
  out.freiburg = 1;
  out.source =
      "TUM freiburg1 (assumed: no camera.yaml in the folder and no freiburg1/2/3 or fr1/2/3 in "
      "its path; --camera FILE to choose)";
  out.assumed = true;
  return out;
}

}  // namespace pnpba
