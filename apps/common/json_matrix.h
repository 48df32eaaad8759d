// Eigen matrices as JSON arrays of rows (row-major), for the CLIs' reports.
#pragma once

#include <Eigen/Core>
#include <nlohmann/json.hpp>

namespace pnpba {

inline nlohmann::json matrixJson(const Eigen::MatrixXd& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (int r = 0; r < m.rows(); ++r) {
    nlohmann::json row = nlohmann::json::array();
    for (int c = 0; c < m.cols(); ++c) row.push_back(m(r, c));
    rows.push_back(row);
  }
  return rows;
}

}  // namespace pnpba
