// The parts of the pnpba Python module, one per room of the library, and the NumPy <-> C++
// conversions they share.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>

namespace pnpba::python {

namespace py = pybind11;

void bindCamera(py::module_& m);
void bindTwoView(py::module_& m);
void bindBal(py::module_& m);
void bindEvaluation(py::module_& m);

// A cv::Mat header over a NumPy image as cv2.imread returns it (no copy when the array is
// C-contiguous; `keep` then owns the data the header points at). `depth`: 2-D uint16;
// otherwise uint8, H x W (grey) or H x W x 3 (BGR). Raises ValueError naming `name` otherwise.
cv::Mat imageView(const py::array& array, const std::string& name, bool depth, py::object* keep);

// A new NumPy array holding a copy of a fixed-size Eigen matrix.
template <int R, int C>
py::array_t<double> toNumpy(const Eigen::Matrix<double, R, C>& m) {
  py::array_t<double> a({R, C});
  auto v = a.template mutable_unchecked<2>();
  for (int r = 0; r < R; ++r)
    for (int c = 0; c < C; ++c) v(r, c) = m(r, c);
  return a;
}

}  // namespace pnpba::python
