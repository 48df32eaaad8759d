#include "pnpba/bal/bal_problem.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <ostream>
#include <random>
#include <sstream>

#include "pnpba/core/error.h"
#include "pnpba/core/parse_number.h"

namespace pnpba {

namespace {

// Whitespace-separated tokens of a whole file, with the line each one is on.
class Tokenizer {
 public:
  Tokenizer(std::string text, std::string path) : text_(std::move(text)), path_(std::move(path)) {}

  bool next(std::string* token) {
    while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) {
      if (text_[pos_] == '\n') ++line_;
      ++pos_;
    }
    if (pos_ >= text_.size()) return false;
    token_line_ = line_;
    const size_t start = pos_;
    while (pos_ < text_.size() && !std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
    *token = text_.substr(start, pos_ - start);
    return true;
  }
  int tokenLine() const { return token_line_; }
  std::string where() const { return path_ + ":" + std::to_string(token_line_) + ": "; }

 private:
  std::string text_, path_;
  size_t pos_ = 0;
  int line_ = 1, token_line_ = 1;
};

// A token as it may be shown in a one-line message: printable, short.
std::string printable(const std::string& token) {
  std::string out;
  for (char c : token.substr(0, 24)) out += std::isprint(static_cast<unsigned char>(c)) ? c : '?';
  return token.size() > 24 ? out + "..." : out;
}

double readNumber(Tokenizer& t, const std::string& what, const std::string& path) {
  std::string token;
  if (!t.next(&token)) throw Error(path + ": truncated: file ends before " + what);
  double v = 0;
  switch (parseNumber(token, &v)) {
    case NumberStatus::kOk:
      return v;
    case NumberStatus::kNotANumber:
      throw Error(t.where() + what + ": '" + printable(token) + "' is not a number");
    case NumberStatus::kNotFinite:
      break;
  }
  throw Error(t.where() + what + ": non-finite value '" + printable(token) + "'");
}

long readInteger(Tokenizer& t, const std::string& what, const std::string& path) {
  std::string token;
  if (!t.next(&token)) throw Error(path + ": truncated: file ends before " + what);
  char* end = nullptr;
  const long v = std::strtol(token.c_str(), &end, 10);
  if (end == token.c_str() || *end != '\0') {
    throw Error(t.where() + what + ": '" + printable(token) + "' is not an integer");
  }
  return v;
}

}  // namespace

double BalProblem::cost() const {
  // Each camera's rotation once, not once per observation (its sines and cosines were most of
  // the time: Ladybug-49 2.5 -> 0.3 ms).
  std::vector<BalCamera> camera_models;
  camera_models.reserve(num_cameras);
  for (int c = 0; c < num_cameras; ++c)
    camera_models.push_back(BalCamera::fromParameters(&cameras[9 * c]));
  double sum = 0;
  for (const BalObservation& o : observations) {
    const BalCamera& c = camera_models[o.camera];
    const Eigen::Vector2d r = Eigen::Vector2d(o.u, o.v) -
                              c.project(Eigen::Map<const Eigen::Vector3d>(&points[3 * o.point]));
    sum += r.squaredNorm();
  }
  return 0.5 * sum;
}

double BalProblem::rmsPixels() const {
  return observations.empty() ? 0.0 : std::sqrt(2.0 * cost() / observations.size());
}

BalProblem readBal(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path + ": cannot open file");
  std::stringstream buffer;
  buffer << in.rdbuf();
  if (buffer.str().find_first_not_of(" \t\r\n") == std::string::npos) {
    throw Error(path + ": empty file");
  }
  Tokenizer t(buffer.str(), path);
  BalProblem p;
  const long nc = readInteger(t, "camera count", path);
  const long np = readInteger(t, "point count", path);
  const long no = readInteger(t, "observation count", path);
  if (nc <= 0 || np <= 0 || no <= 0) {
    throw Error(t.where() + "header counts must be positive (cameras points observations)");
  }
  // Every value but the last takes at least two bytes ("0 "): a count no file of this size
  // could hold is refused before anything is allocated for it. Within that, storage grows as
  // values are read, so a short file is reported as truncated where it ends.
  const long max_values = static_cast<long>((buffer.str().size() + 1) / 2);
  if (no > max_values || nc > max_values || np > max_values) {
    throw Error(t.where() + "header counts " + std::to_string(nc) + " " + std::to_string(np) + " " +
                std::to_string(no) + " need more values than the file holds");
  }
  p.num_cameras = static_cast<int>(nc);
  p.num_points = static_cast<int>(np);
  p.observations.resize(std::min(no, max_values / 4));
  std::vector<char> camera_seen(nc, 0), point_seen(np, 0);
  for (long i = 0; i < no; ++i) {
    if (i == static_cast<long>(p.observations.size())) p.observations.emplace_back();
    BalObservation& o = p.observations[i];
    const long c = readInteger(t, "observation camera index", path);
    const int line = t.tokenLine();
    if (c < 0) throw Error(t.where() + "negative camera index " + std::to_string(c));
    if (c >= nc) {
      throw Error(t.where() + "camera index " + std::to_string(c) + " out of range (" +
                  std::to_string(nc) + " cameras)");
    }
    const long q = readInteger(t, "observation point index", path);
    if (q < 0) throw Error(t.where() + "negative point index " + std::to_string(q));
    if (q >= np) {
      throw Error(t.where() + "point index " + std::to_string(q) + " out of range (" +
                  std::to_string(np) + " points)");
    }
    o.camera = static_cast<int>(c);
    o.point = static_cast<int>(q);
    o.u = readNumber(t, "observation u", path);
    o.v = readNumber(t, "observation v", path);
    if (t.tokenLine() != line) {
      throw Error(t.where() + "observation split across lines (expected 'camera point u v')");
    }
    camera_seen[c] = point_seen[q] = 1;
  }
  for (long i = 0; i < 9 * nc; ++i) p.cameras.push_back(readNumber(t, "camera parameter", path));
  for (long i = 0; i < 3 * np; ++i) p.points.push_back(readNumber(t, "point coordinate", path));
  std::string extra;
  if (t.next(&extra)) {
    throw Error(t.where() + "trailing data after the last point: '" + printable(extra) + "'");
  }
  for (long c = 0; c < nc; ++c) {
    if (!camera_seen[c])
      throw Error(path + ": camera " + std::to_string(c) + " has no observation");
  }
  for (long q = 0; q < np; ++q) {
    if (!point_seen[q]) throw Error(path + ": point " + std::to_string(q) + " has no observation");
  }
  return p;
}

void writeBal(std::ostream& out, const BalProblem& p) {
  out << p.num_cameras << " " << p.num_points << " " << p.observations.size() << "\n";
  char line[128];
  for (const BalObservation& o : p.observations) {
    std::snprintf(line, sizeof line, "%d %d %.17g %.17g\n", o.camera, o.point, o.u, o.v);
    out << line;
  }
  for (double v : p.cameras) {
    std::snprintf(line, sizeof line, "%.17g\n", v);
    out << line;
  }
  for (double v : p.points) {
    std::snprintf(line, sizeof line, "%.17g\n", v);
    out << line;
  }
}

void writeBalPly(std::ostream& out, const BalProblem& p, bool binary) {
  out << "ply\nformat " << (binary ? "binary_little_endian" : "ascii") << " 1.0\n"
      << "comment pnpba BAL export: camera centres green, points white\n"
      << "element vertex " << p.num_cameras + p.num_points << "\n"
      << "property float x\nproperty float y\nproperty float z\n"
      << "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n";
  auto vertex = [&](const Eigen::Vector3d& x, unsigned char r, unsigned char g, unsigned char b) {
    if (binary) {
      const float xyz[3] = {static_cast<float>(x.x()), static_cast<float>(x.y()),
                            static_cast<float>(x.z())};
      const unsigned char rgb[3] = {r, g, b};
      out.write(reinterpret_cast<const char*>(xyz), sizeof xyz);  // little-endian host
      out.write(reinterpret_cast<const char*>(rgb), sizeof rgb);
    } else {
      out << x.x() << " " << x.y() << " " << x.z() << " " << int(r) << " " << int(g) << " "
          << int(b) << "\n";
    }
  };
  for (int c = 0; c < p.num_cameras; ++c) {
    vertex(BalCamera::fromParameters(&p.cameras[9 * c]).pose.inverse().translation(), 0, 255, 0);
  }
  for (int q = 0; q < p.num_points; ++q) {
    vertex(Eigen::Map<const Eigen::Vector3d>(&p.points[3 * q]), 255, 255, 255);
  }
}

void normalizeBal(BalProblem& p) {
  auto median = [](std::vector<double> v) {
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  };
  Eigen::Vector3d centre;
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<double> values(p.num_points);
    for (int q = 0; q < p.num_points; ++q) values[q] = p.points[3 * q + axis];
    centre[axis] = median(values);
  }
  std::vector<double> deviation(p.num_points);
  for (int q = 0; q < p.num_points; ++q) {
    deviation[q] = (Eigen::Map<const Eigen::Vector3d>(&p.points[3 * q]) - centre).lpNorm<1>();
  }
  const double mad = median(deviation);
  const double scale = mad > 0 ? 100.0 / mad : 1.0;
  for (int q = 0; q < p.num_points; ++q) {
    Eigen::Map<Eigen::Vector3d> X(&p.points[3 * q]);
    X = scale * (X - centre);
  }
  for (int c = 0; c < p.num_cameras; ++c) {
    BalCamera cam = BalCamera::fromParameters(&p.cameras[9 * c]);
    const Eigen::Vector3d centre_c = scale * (cam.pose.inverse().translation() - centre);
    cam.pose.setTranslation(-(cam.pose.rotation() * centre_c));
    cam.toParameters(&p.cameras[9 * c]);
  }
}

void perturbBal(BalProblem& p, const BalPerturbation& s) {
  std::mt19937_64 rng(s.seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  for (int q = 0; q < p.num_points && s.point_sigma > 0; ++q) {
    for (int k = 0; k < 3; ++k) p.points[3 * q + k] += s.point_sigma * gauss(rng);
  }
  for (int c = 0; c < p.num_cameras; ++c) {
    double* params = &p.cameras[9 * c];
    // The centre is perturbed in the world frame, as Ceres's example does.
    Eigen::Vector3d centre = BalCamera::fromParameters(params).pose.inverse().translation();
    if (s.rotation_sigma > 0) {
      for (int k = 0; k < 3; ++k) params[k] += s.rotation_sigma * gauss(rng);
    }
    if (s.translation_sigma > 0) {
      for (int k = 0; k < 3; ++k) centre[k] += s.translation_sigma * gauss(rng);
    }
    BalCamera cam = BalCamera::fromParameters(params);
    cam.pose.setTranslation(-(cam.pose.rotation() * centre));
    for (int k = 3; k < 6; ++k) params[k] = cam.pose.translation()[k - 3];
  }
}

void buildBalGraph(SparseOptimizer& optimizer, const BalProblem& p, const std::string& kernel) {
  if (kernel != "none" && kernel != "huber" && kernel != "cauchy") {
    throw Error("unknown robust loss '" + kernel + "' (expected none, huber or cauchy)");
  }
  std::vector<VertexBalCamera*> cameras(p.num_cameras);
  for (int c = 0; c < p.num_cameras; ++c) {
    cameras[c] = new VertexBalCamera();
    cameras[c]->setId(c);
    cameras[c]->setEstimate(BalCamera::fromParameters(&p.cameras[9 * c]));
    optimizer.addVertex(cameras[c]);
  }
  std::vector<VertexPointXYZ*> points(p.num_points);
  for (int q = 0; q < p.num_points; ++q) {
    points[q] = new VertexPointXYZ();
    points[q]->setId(p.num_cameras + q);
    points[q]->setEstimate(Eigen::Map<const Eigen::Vector3d>(&p.points[3 * q]));
    points[q]->setMarginalized(true);
    optimizer.addVertex(points[q]);
  }
  int id = 0;
  for (const BalObservation& o : p.observations) {
    auto* e = new EdgeBalProjection();
    e->setId(id++);
    e->setVertex(0, points[o.point]);
    e->setVertex(1, cameras[o.camera]);
    e->setMeasurement(Eigen::Vector2d(o.u, o.v));
    if (kernel == "huber") e->setRobustKernel(new RobustKernelHuber(1.0));
    if (kernel == "cauchy") e->setRobustKernel(new RobustKernelCauchy(1.0));
    optimizer.addEdge(e);
  }
}

void readBalGraph(const SparseOptimizer& optimizer, BalProblem& p) {
  for (int c = 0; c < p.num_cameras; ++c) {
    static_cast<const VertexBalCamera*>(optimizer.vertex(c))
        ->estimate()
        .toParameters(&p.cameras[9 * c]);
  }
  for (int q = 0; q < p.num_points; ++q) {
    Eigen::Map<Eigen::Vector3d>(&p.points[3 * q]) =
        static_cast<const VertexPointXYZ*>(optimizer.vertex(p.num_cameras + q))->estimate();
  }
}

}  // namespace pnpba
