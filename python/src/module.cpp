// The pnpba Python module: the two-view RGB-D pose, BAL bundle adjustment and TUM evaluation
// with NumPy arrays in and out. pnpba.Error (a ValueError) carries the library's one-line
// messages.
#include "bindings.h"
#include "pnpba/core/error.h"

PYBIND11_MODULE(_pnpba, m) {
  namespace py = pybind11;
  m.doc() =
      "pnpba: two-view RGB-D camera pose (features + depth, EPnP RANSAC, bundle adjustment, "
      "depth-only registration where texture fails) with its covariance; BAL bundle "
      "adjustment; evaluation on TUM RGB-D sequences.";
  py::register_exception<pnpba::Error>(m, "Error", PyExc_ValueError).attr("__doc__") =
      "pnpba's one-line error for bad input or options, naming the file (and line) or the "
      "argument; a ValueError.";
  pnpba::python::bindCamera(m);
  pnpba::python::bindTwoView(m);
  pnpba::python::bindBal(m);
  pnpba::python::bindEvaluation(m);
}
