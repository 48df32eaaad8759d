#include "bindings.h"

namespace pnpba::python {

namespace {

std::string shapeText(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) s += (i ? ", " : "") + std::to_string(a.shape(i));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

}  // namespace

cv::Mat imageView(const py::handle& object, const std::string& name, bool depth, py::object* keep) {
  // Anything but an array (a list, a PIL image, a path) is named here in one line, where
  // pybind11's own message would print every argument's contents.
  if (!py::isinstance<py::array>(object)) {
    throw py::type_error(name + ": expected a NumPy array (as cv2.imread returns it), got " +
                         std::string(py::str(py::type::handle_of(object).attr("__name__"))));
  }
  const py::array array = py::reinterpret_borrow<py::array>(object);
  const std::string dtype = py::str(array.dtype());
  if (depth) {
    if (!array.dtype().is(py::dtype::of<uint16_t>())) {
      throw py::value_error(name + ": depth must be uint16 (cv2.IMREAD_UNCHANGED), got " + dtype);
    }
    if (array.ndim() != 2) {
      throw py::value_error(name + ": depth must be 2-D (H, W), got shape " + shapeText(array));
    }
  } else {
    if (!array.dtype().is(py::dtype::of<uint8_t>())) {
      throw py::value_error(name + ": image must be uint8 (as cv2.imread returns it), got " +
                            dtype);
    }
    if (!(array.ndim() == 2 || (array.ndim() == 3 && array.shape(2) == 3))) {
      throw py::value_error(name + ": image must be (H, W) grey or (H, W, 3) BGR, got shape " +
                            shapeText(array));
    }
  }
  if (array.shape(0) == 0 || array.shape(1) == 0) throw py::value_error(name + ": empty image");
  // A view when the rows are C-contiguous, one copy otherwise (e.g. a slice of another image).
  py::array contiguous = py::array::ensure(array, py::array::c_style);
  if (!contiguous) throw py::value_error(name + ": cannot read the array");
  *keep = contiguous;
  const int type = depth ? CV_16UC1 : (array.ndim() == 2 ? CV_8UC1 : CV_8UC3);
  return cv::Mat(static_cast<int>(contiguous.shape(0)), static_cast<int>(contiguous.shape(1)), type,
                 const_cast<void*>(contiguous.data()), static_cast<size_t>(contiguous.strides(0)));
}

}  // namespace pnpba::python
