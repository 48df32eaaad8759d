#include <pybind11/functional.h>
#include <pybind11/stl.h>

#include <filesystem>

#include "bindings.h"
#include "pnpba/evaluation/tum_cameras.h"
#include "pnpba/evaluation/tum_dataset.h"
#include "pnpba/evaluation/tum_evaluation.h"

namespace pnpba::python {

namespace {

// The per-method table as dicts (the rows evaluate_tum prints), and every pair's record.
py::dict evaluate(const std::string& folder, const std::vector<std::string>& methods, int max_gap,
                  int features, const std::string& camera, double gt_offset, double focal_sigma,
                  double principal_point_sigma, double depth_scale_sigma, double motion_sigma,
                  double motion_cap_deg, double motion_cap_cm, bool fuse_agreeing,
                  const py::object& progress) {
  TumEvaluationOptions o;
  o.folder = folder, o.max_gap = max_gap, o.features = features, o.camera_path = camera;
  o.gt_offset_s = gt_offset;
  o.covariance.focal_sigma = focal_sigma;
  o.covariance.principal_point_sigma_px = principal_point_sigma;
  o.covariance.depth_scale_sigma = depth_scale_sigma;
  o.covariance.motion_sigma = motion_sigma;
  o.covariance.motion_cap_deg = motion_cap_deg;
  o.covariance.motion_cap_m = motion_cap_cm / 100.0;
  o.covariance.fuse_agreeing_poses = fuse_agreeing;
  if (!methods.empty()) o.methods = methods;
  std::function<void(const std::string&)> on_line;
  if (!progress.is_none()) {
    on_line = [&progress](const std::string& line) {
      py::gil_scoped_acquire acquire;
      progress(line);
    };
  }
  TumEvaluation ev;
  {
    py::gil_scoped_release release;
    ev = evaluateTumSequence(o, on_line);
  }
  // One JSON assembly for the CLI and Python: the report's own fields, as Python objects.
  const py::dict report = py::module_::import("json").attr("loads")(evaluationJson(ev));
  py::list table;
  for (const auto& item : report["methods"].cast<py::dict>()) {
    py::dict row;
    row["method"] = item.first;
    for (const auto& field : item.second.cast<py::dict>()) row[field.first] = field.second;
    table.append(row);
  }
  py::dict out;
  out["methods"] = table;
  out["pairs"] = report["pairs"];
  out["frames"] = ev.frames;
  out["camera"] = ev.camera;
  out["plugin_load_ms"] = ev.plugin_load_ms;
  return out;
}

// The frames of a TUM folder by evaluate_tum's rules, with absolute paths.
py::list tumFrames(const std::string& folder) {
  TumSequence seq;
  {
    py::gil_scoped_release release;
    seq = loadTumSequence(folder);
  }
  const std::filesystem::path base = std::filesystem::absolute(folder);
  py::list frames;
  for (const TumFrame& f : seq.frames) {
    py::dict d;
    d["rgb_stamp"] = f.rgb_stamp;
    d["rgb"] = (base / f.rgb).lexically_normal().string();
    d["depth_stamp"] = f.depth_stamp;
    d["depth"] = (base / f.depth).lexically_normal().string();
    frames.append(d);
  }
  return frames;
}

}  // namespace

void bindEvaluation(py::module_& m) {
  m.def(
      "tum_frames", &tumFrames, py::arg("folder"),
      R"doc(The frames of a TUM RGB-D folder in time order, by evaluate_tum's rules: associate.txt,
else rgb.txt + depth.txt associated by nearest stamp within 0.02 s, or a key-frame folder's
poses.txt; frames whose files are missing are left out. Returns [{'rgb_stamp', 'rgb',
'depth_stamp', 'depth'}] with absolute paths. Raises pnpba.Error for a bad folder or list.)doc");
  m.def("tum_freiburg1_camera", &tumFreiburg1Camera, "The TUM freiburg1 camera (tum_camera(1)).");
  m.def("tum_camera", &tumFreiburgCamera, py::arg("freiburg"),
        "The TUM RGB-D benchmark's freiburg 1, 2 or 3 camera (its published calibration; "
        "freiburg3's images come undistorted). Raises pnpba.Error for another number.");
  m.def(
      "tum_camera_for_folder",
      [](const std::string& folder, const std::string& camera) {
        const SequenceCamera c = sequenceCamera(folder, camera);
        py::dict out;
        out["camera"] = c.camera, out["source"] = c.source;
        out["freiburg"] = c.freiburg, out["assumed"] = c.assumed;
        return out;
      },
      py::arg("folder"), py::arg("camera") = "",
      R"doc(The camera evaluate_tum and pnpba-batch use for a TUM folder, as a dict: 'camera',
'source' (which rule chose it, for a user to read), 'freiburg' (1-3 when a TUM camera was taken,
0 for a YAML) and 'assumed'. In order: the `camera` YAML if given, FOLDER/camera.yaml, the
freiburg camera the folder's path names ('rgbd_dataset_freiburg3_cabinet',
'tum_fr3_cabinet_keyframes'), else freiburg1 with 'assumed' True.)doc");
  m.def("evaluate_tum", &evaluate, py::arg("folder"), py::kw_only(),
        py::arg("methods") = std::vector<std::string>{}, py::arg("max_gap") = 8,
        py::arg("features") = 1500, py::arg("camera") = "", py::arg("gt_offset") = 0.0,
        py::arg("focal_sigma") = CovarianceModelOptions{}.focal_sigma,
        py::arg("principal_point_sigma") = CovarianceModelOptions{}.principal_point_sigma_px,
        py::arg("depth_scale_sigma") = CovarianceModelOptions{}.depth_scale_sigma,
        py::arg("motion_sigma") = CovarianceModelOptions{}.motion_sigma,
        py::arg("motion_cap_deg") = CovarianceModelOptions{}.motion_cap_deg,
        py::arg("motion_cap_cm") = CovarianceModelOptions{}.motion_cap_m * 100.0,
        py::arg("fuse_agreeing") = CovarianceModelOptions{}.fuse_agreeing_poses,
        py::arg("progress") = py::none(),
        R"doc(Every pair (i, i+k), 1 <= k <= max_gap, of a TUM RGB-D sequence with each method,
scored against the ground truth (evaluate_tum's work).

methods: BA modes ('rgbd', 'pose', 'none', 'textbook', 'two-camera'), 'opencv' and 'open3d'
(Open3D's RGB-D odometry); empty: all
of evaluate_tum's defaults. camera: a camera YAML path ('' = folder/camera.yaml or TUM fr1).
focal_sigma, principal_point_sigma, depth_scale_sigma, motion_sigma, motion_cap_deg,
motion_cap_cm, fuse_agreeing: the covariance model's options, as estimate_two_view takes them. progress(line) gets one line per pair. Returns {'methods': [one dict per method: method,
pairs, failures, success_rate, median_rot_deg, median_trans_cm, ...], 'pairs': [...],
'frames': n, 'camera': source, 'plugin_load_ms': ms (the depth path's plugin, opened before the
first pair; -1 when no method needed it)}.)doc");
}

}  // namespace pnpba::python
