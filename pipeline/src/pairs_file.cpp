#include "pnpba/pipeline/pairs_file.h"

#include <cmath>
#include <fstream>
#include <sstream>

#include "pnpba/core/error.h"
#include "pnpba/core/parse_number.h"

namespace pnpba {

PairsFile readPairsFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error(path + ": cannot open file");
  PairsFile file;
  std::string line;
  int line_no = 0;
  int columns_seen = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const std::string where = path + ":" + std::to_string(line_no) + ": ";
    const auto hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    std::istringstream fields(line);
    std::vector<double> values;
    std::string token;
    while (fields >> token) {
      values.push_back(numberOrThrow(token, where));
    }
    if (values.empty()) continue;
    const int n = static_cast<int>(values.size());
    if (n != 5 && n != 7) {
      throw Error(where + "expected 5 (X Y Z u2 v2) or 7 (... u1 v1) numbers, got " +
                  std::to_string(n));
    }
    if (columns_seen != 0 && n != columns_seen) {
      throw Error(where + "has " + std::to_string(n) + " numbers, earlier lines " +
                  std::to_string(columns_seen));
    }
    columns_seen = n;
    if (!(values[2] > 0)) throw Error(where + "depth Z must be > 0");
    PointPair p;
    p.X_1 = Eigen::Vector3d(values[0], values[1], values[2]);
    p.uv_2 = Eigen::Vector2d(values[3], values[4]);
    p.uv_1 = n == 7 ? Eigen::Vector2d(values[5], values[6]) : Eigen::Vector2d::Constant(NAN);
    file.pairs.push_back(p);
  }
  if (in.bad()) throw Error(path + ": read error");
  if (file.pairs.empty()) throw Error(path + ": no pairs in file");
  file.has_image1_pixels = columns_seen == 7;
  return file;
}

}  // namespace pnpba
