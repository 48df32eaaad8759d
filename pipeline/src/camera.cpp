#include "pnpba/pipeline/camera.h"

#include <cmath>
#include <fstream>
#include <map>

#include "pnpba/core/error.h"
#include "pnpba/core/parse_number.h"

namespace pnpba {

std::string Camera::validate() const {
  std::string p = pinhole.validate();
  if (!p.empty()) return p;
  if (!std::isfinite(depth_scale) || !(depth_scale > 0)) return "depth scale must be > 0";
  if (width < 0 || height < 0) return "image size must be >= 0";
  return "";
}

namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

}  // namespace

Camera loadCameraYaml(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error(path + ": cannot open file");
  std::map<std::string, double> values;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const std::string where = path + ":" + std::to_string(line_no) + ": ";
    const auto hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    const std::string text = trim(line);
    if (text.empty() || text[0] == '%' || text == "---") continue;
    const auto colon = text.find(':');
    if (colon == std::string::npos) throw Error(where + "expected 'key: value'");
    const std::string key = trim(text.substr(0, colon));
    const std::string value = trim(text.substr(colon + 1));
    const bool wanted = key.rfind("Camera.", 0) == 0 || key == "DepthMapFactor";
    if (!wanted || value.empty()) continue;
    double v = 0;
    const NumberStatus status = parseNumber(value, &v);
    if (status == NumberStatus::kNotANumber) {
      // Non-numeric Camera.* entries (e.g. Camera.RGB, Camera.type) are not ours to read.
      const bool numeric_key = key == "DepthMapFactor" || key == "Camera.fx" ||
                               key == "Camera.fy" || key == "Camera.cx" || key == "Camera.cy" ||
                               key == "Camera.k1" || key == "Camera.k2" || key == "Camera.p1" ||
                               key == "Camera.p2" || key == "Camera.k3" || key == "Camera.width" ||
                               key == "Camera.height";
      if (numeric_key) throw Error(where + key + ": '" + value + "' is not a number");
      continue;
    }
    if (status == NumberStatus::kNotFinite) throw Error(where + key + ": value is not finite");
    values[key] = v;
  }
  for (const char* required : {"Camera.fx", "Camera.fy", "Camera.cx", "Camera.cy"}) {
    if (values.count(required) == 0) throw Error(path + ": missing " + required);
  }
  auto get = [&](const std::string& k, double fallback) {
    auto it = values.find(k);
    return it == values.end() ? fallback : it->second;
  };
  Camera c;
  c.pinhole.fx = values["Camera.fx"];
  c.pinhole.fy = values["Camera.fy"];
  c.pinhole.cx = values["Camera.cx"];
  c.pinhole.cy = values["Camera.cy"];
  c.pinhole.distortion = {get("Camera.k1", 0), get("Camera.k2", 0), get("Camera.p1", 0),
                          get("Camera.p2", 0), get("Camera.k3", 0)};
  c.depth_scale = get("DepthMapFactor", 5000.0);
  // A size is a whole number of pixels; anything else (or beyond int) is refused, not cast.
  auto size = [&](const char* key) {
    const double v = get(key, 0);
    if (!(v >= 0 && v <= 1e6 && v == std::floor(v))) {
      throw Error(path + ": " + key + " must be a whole number of pixels in 0..1000000");
    }
    return static_cast<int>(v);
  };
  c.width = size("Camera.width");
  c.height = size("Camera.height");
  const std::string problem = c.validate();
  if (!problem.empty()) throw Error(path + ": " + problem);
  return c;
}

}  // namespace pnpba
