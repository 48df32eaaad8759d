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
// otherwise uint8, H x W (grey) or H x W x 3 (BGR). Raises ValueError naming `name` otherwise,
// TypeError when `object` is not a NumPy array.
cv::Mat imageView(const py::handle& object, const std::string& name, bool depth, py::object* keep);

// A new NumPy array holding a copy of a fixed-size Eigen matrix.
template <int R, int C>
py::array_t<double> toNumpy(const Eigen::Matrix<double, R, C>& m) {
  py::array_t<double> a({R, C});
  auto v = a.template mutable_unchecked<2>();
  for (int r = 0; r < R; ++r)
    for (int c = 0; c < C; ++c) v(r, c) = m(r, c);
  return a;
}

// A new n x width NumPy array (1-D when width is 0) filled by value(row, column): the copies of
// per-item fields (keypoints, pairs, observations) the results expose.
template <typename T, typename F>
py::array_t<T> tableOf(size_t n, py::ssize_t width, F value) {
  if (width == 0) {
    py::array_t<T> a(static_cast<py::ssize_t>(n));
    auto v = a.template mutable_unchecked<1>();
    for (size_t i = 0; i < n; ++i) v(i) = value(i, 0);
    return a;
  }
  py::array_t<T> a({static_cast<py::ssize_t>(n), width});
  auto v = a.template mutable_unchecked<2>();
  for (size_t i = 0; i < n; ++i)
    for (py::ssize_t k = 0; k < width; ++k) v(i, k) = value(i, k);
  return a;
}

}  // namespace pnpba::python
