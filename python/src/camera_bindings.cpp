#include <pybind11/stl.h>

#include <array>
#include <sstream>

#include "bindings.h"
#include "pnpba/core/error.h"
#include "pnpba/pipeline/camera.h"

namespace pnpba::python {

namespace {

Camera makeCamera(double fx, double fy, double cx, double cy, const std::array<double, 5>& d,
                  double depth_scale, int width, int height) {
  Camera c;
  c.pinhole.fx = fx, c.pinhole.fy = fy, c.pinhole.cx = cx, c.pinhole.cy = cy;
  std::copy(d.begin(), d.end(), c.pinhole.distortion.begin());
  c.depth_scale = depth_scale;
  c.width = width, c.height = height;
  const std::string problem = c.validate();
  if (!problem.empty()) throw Error("camera: " + problem);
  return c;
}

std::string describe(const Camera& c) {
  std::ostringstream s;
  s << "Camera(fx=" << c.pinhole.fx << ", fy=" << c.pinhole.fy << ", cx=" << c.pinhole.cx
    << ", cy=" << c.pinhole.cy << ", distortion=(";
  for (int i = 0; i < 5; ++i) s << (i ? ", " : "") << c.pinhole.distortion[i];
  s << "), depth_scale=" << c.depth_scale << ")";
  return s.str();
}

}  // namespace

void bindCamera(py::module_& m) {
  py::class_<Camera>(m, "Camera",
                     "Pinhole camera with OpenCV distortion (k1, k2, p1, p2, k3) and the depth "
                     "images' scale (depth value per metre: 5000 for TUM, 1000 for most "
                     "Kinect-style sensors).")
      .def(py::init(&makeCamera), py::arg("fx"), py::arg("fy"), py::arg("cx"), py::arg("cy"),
           py::arg("distortion") = std::array<double, 5>{0, 0, 0, 0, 0},
           py::arg("depth_scale") = 5000.0, py::arg("width") = 0, py::arg("height") = 0,
           "Raises pnpba.Error (a ValueError) for non-finite or zero focal lengths, a "
           "non-positive depth scale and the like.")
      .def_static("from_yaml", &loadCameraYaml, py::arg("path"),
                  "Reads an ORB-SLAM2-style settings file (Camera.fx, ..., DepthMapFactor).")
      .def_property_readonly("fx", [](const Camera& c) { return c.pinhole.fx; })
      .def_property_readonly("fy", [](const Camera& c) { return c.pinhole.fy; })
      .def_property_readonly("cx", [](const Camera& c) { return c.pinhole.cx; })
      .def_property_readonly("cy", [](const Camera& c) { return c.pinhole.cy; })
      .def_property_readonly(
          "distortion",
          [](const Camera& c) {
            return std::array<double, 5>{c.pinhole.distortion[0], c.pinhole.distortion[1],
                                         c.pinhole.distortion[2], c.pinhole.distortion[3],
                                         c.pinhole.distortion[4]};
          },
          "(k1, k2, p1, p2, k3)")
      .def_property_readonly("depth_scale", [](const Camera& c) { return c.depth_scale; })
      .def_property_readonly("width", [](const Camera& c) { return c.width; })
      .def_property_readonly("height", [](const Camera& c) { return c.height; })
      .def_property_readonly(
          "K",
          [](const Camera& c) {
            Eigen::Matrix3d K;
            K << c.pinhole.fx, 0, c.pinhole.cx, 0, c.pinhole.fy, c.pinhole.cy, 0, 0, 1;
            return toNumpy(K);
          },
          "3x3 intrinsic matrix")
      .def("__repr__", &describe);
}

}  // namespace pnpba::python
