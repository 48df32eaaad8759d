#include <pybind11/stl.h>

#include <Eigen/Cholesky>
#include <cmath>
#include <set>

#include "bindings.h"
#include "pnpba/core/error.h"
#include "pnpba/pipeline/depth_registration.h"
#include "pnpba/pipeline/two_view.h"
#include "pnpba/pipeline/two_view_report.h"

namespace pnpba::python {

namespace {

// A result together with the BA mode it was refined with (the JSON report names it).
struct PyTwoViewResult {
  TwoViewResult r;
  std::string ba_mode;
};

const std::set<std::string> kOptionNames = {"preset",
                                            "features",
                                            "max_feature_pixels",
                                            "detector",
                                            "match_filter",
                                            "ransac_threshold",
                                            "ba",
                                            "solver",
                                            "depth_path",
                                            "undistort",
                                            "retry_with_sift",
                                            "max_sigma_deg",
                                            "max_sigma_cm",
                                            "focal_sigma",
                                            "principal_point_sigma",
                                            "depth_scale_sigma",
                                            "motion_sigma",
                                            "motion_cap_deg",
                                            "motion_cap_cm",
                                            "fuse_agreeing",
                                            "brightness_gain_sigma",
                                            "time_budget_ms"};

// The CLI's options as keyword arguments, applied in the CLI's order: the preset first, then
// each named option over it.
TwoViewOptions optionsFrom(const py::kwargs& kwargs, std::string* ba_mode,
                           const char* function = "estimate_two_view") {
  for (const auto& item : kwargs) {
    const std::string key = py::str(item.first);
    if (!kOptionNames.count(key)) {
      throw py::type_error(std::string(function) + "() got an unexpected keyword argument '" + key +
                           "'");
    }
  }
  TwoViewOptions o;
  *ba_mode = "rgbd";
  if (kwargs.contains("preset")) {
    const std::string preset = kwargs["preset"].cast<std::string>();
    if (preset != "textbook") throw Error("preset: unknown preset '" + preset + "'");
    o = TwoViewOptions::textbookPreset();
    *ba_mode = "textbook";
  }
  auto get = [&kwargs](const char* key, auto* value) {
    if (!kwargs.contains(key)) return false;
    try {
      *value = kwargs[key].cast<std::remove_pointer_t<decltype(value)>>();
    } catch (const py::cast_error&) {
      throw py::type_error(std::string("estimate_two_view() argument '") + key + "': got " +
                           std::string(py::str(py::type::of(kwargs[key]).attr("__name__"))));
    }
    return true;
  };
  get("features", &o.orb.num_features);
  get("max_feature_pixels", &o.orb.max_pixels);
  get("ransac_threshold", &o.ransac.threshold_px);
  get("undistort", &o.undistort);
  get("retry_with_sift", &o.retry_with_sift);
  get("max_sigma_deg", &o.failure_rule.max_sigma_deg);
  get("max_sigma_cm", &o.failure_rule.max_sigma_cm);
  get("focal_sigma", &o.covariance.focal_sigma);
  get("principal_point_sigma", &o.covariance.principal_point_sigma_px);
  get("depth_scale_sigma", &o.covariance.depth_scale_sigma);
  get("motion_sigma", &o.covariance.motion_sigma);
  get("motion_cap_deg", &o.covariance.motion_cap_deg);
  double motion_cap_cm = 0;
  if (get("motion_cap_cm", &motion_cap_cm)) o.covariance.motion_cap_m = motion_cap_cm / 100.0;
  get("fuse_agreeing", &o.covariance.fuse_agreeing_poses);
  get("time_budget_ms", &o.time_budget_ms);
  if (get("brightness_gain_sigma", &o.rgbd_alignment.brightness_gain_sigma)) {
    o.alignment_evidence.brightness_gain_sigma = o.rgbd_alignment.brightness_gain_sigma;
  }
  std::string text;
  if (get("detector", &text)) o.orb.detector = parseDetector(text);
  if (get("match_filter", &text)) o.matching.filter = parseMatchFilter(text);
  get("ba", ba_mode);
  o.refinement.mode = parseBundleMode(*ba_mode);
  if (get("solver", &text)) o.refinement.solver = parseSolverBackend(text);
  if (get("depth_path", &text)) o.depth_path = parseDepthPath(text);
  const std::string problem = o.validate();
  if (!problem.empty()) throw Error(problem);
  return o;
}

// A frame's features (describeFrame) as given from Python: None, or a FrameFeatures.
const FrameFeatures* givenFeatures(const py::object& value, const char* name) {
  if (value.is_none()) return nullptr;
  if (!py::isinstance<FrameFeatures>(value)) {
    throw py::type_error(std::string("estimate_two_view() argument '") + name +
                         "': expected a FrameFeatures (pnpba.describe_frame) or None, got " +
                         std::string(py::str(py::type::of(value).attr("__name__"))));
  }
  return &value.cast<const FrameFeatures&>();
}

FrameFeatures describe(const py::object& image, const py::kwargs& kwargs) {
  std::string ba_mode;
  const TwoViewOptions options = optionsFrom(kwargs, &ba_mode, "describe_frame");
  py::object keep;
  const cv::Mat view = imageView(image, "image", false, &keep);
  py::gil_scoped_release release;
  return describeFrame(view, options.orb);
}

PyTwoViewResult estimate(const py::object& image1, const py::object& depth1,
                         const py::object& image2, const py::object& depth2, const Camera& camera,
                         const py::object& features1, const py::object& features2,
                         const py::kwargs& kwargs) {
  PyTwoViewResult out;
  const TwoViewOptions options = optionsFrom(kwargs, &out.ba_mode);
  py::object keep1, keep2, keep3, keep4;
  const cv::Mat i1 = imageView(image1, "image1", false, &keep1);
  const cv::Mat d1 = imageView(depth1, "depth1", true, &keep2);
  const cv::Mat i2 = imageView(image2, "image2", false, &keep3);
  const cv::Mat d2 = depth2.is_none() ? cv::Mat() : imageView(depth2, "depth2", true, &keep4);
  checkTwoViewInputs(i1, d1, i2, d2, {"image1", "image2", "depth1", "depth2"});
  const FrameFeatures* given1 = givenFeatures(features1, "features1");
  const FrameFeatures* given2 = givenFeatures(features2, "features2");
  // The arrays stay referenced by keep1..4, the features by features1 and 2, while the estimate
  // runs without the GIL.
  py::gil_scoped_release release;
  out.r = estimateTwoView(i1, d1, i2, d2, camera, options, given1, given2);
  return out;
}

py::object poseOrNone(const PyTwoViewResult& p, const SE3Quat& T) {
  if (!p.r.ok) return py::none();
  return toNumpy(T.to_homogeneous_matrix());
}

py::object measuredOrNone(double value) { return value < 0 ? py::none() : py::cast(value); }

py::array_t<double> keypointArray(const std::vector<cv::KeyPoint>& keypoints) {
  return tableOf<double>(keypoints.size(), 2, [&](size_t i, int k) {
    return k == 0 ? keypoints[i].pt.x : keypoints[i].pt.y;
  });
}

}  // namespace

void bindTwoView(py::module_& m) {
  py::class_<FrameFeatures>(
      m, "FrameFeatures",
      "A frame's features, found once by describe_frame and given to estimate_two_view for "
      "every pair the frame is in.")
      .def_property_readonly(
          "keypoints", [](const FrameFeatures& f) { return keypointArray(f.features.keypoints); },
          "(N, 2) float64 pixel positions")
      .def_property_readonly(
          "size",
          [](const FrameFeatures& f) { return py::make_tuple(f.size.width, f.size.height); },
          "the image's (width, height)")
      .def_property_readonly(
          "later_features",
          [](const FrameFeatures& f) { return f.later ? f.later->size() : size_t{0}; },
          "how many other feature sets estimates found for this frame and kept in it for its "
          "next pairs (the SIFT retry's: 0 or 1)")
      .def_property_readonly(
          "later_depth_descriptions",
          [](const FrameFeatures& f) { return f.later ? f.later->depthSize() : size_t{0}; },
          "how many descriptions of this frame's depth (cloud, normals, FPFH descriptors) the "
          "depth registration made with it as image1 and kept in it for its next pairs (0 or 1 "
          "under one set of options)")
      .def("__repr__", [](const FrameFeatures& f) {
        return "FrameFeatures(" + std::to_string(f.features.keypoints.size()) + " keypoints, " +
               std::to_string(f.size.width) + "x" + std::to_string(f.size.height) + ")";
      });
  m.def(
      "describe_frame", &describe, py::arg("image"),
      R"doc(The features estimate_two_view finds in this image (BGR or grey uint8) with these keyword
options (the feature options of estimate_two_view: preset, features, max_feature_pixels,
detector; the others are accepted and change nothing here), found once: an odometry loop's frame
is image2 of one pair and image1 of the next, and estimate_two_view(..., features1=,
features2=) skips their detection and returns the same answer. An estimate that retries with
SIFT keeps the given frames' SIFT features in them for their next pairs (about 1.5 MB a 640 x 480
frame), and one that registers the depths keeps image1's depth description in features1 (about
1 MB): a key frame's next pairs skip half the registration's preparation. Features of another
image, or
found with other options than the estimate's, raise pnpba.Error. The GIL is released while it
runs.)doc");
  py::class_<PyTwoViewResult>(m, "TwoViewResult",
                              "The two-view estimate. When ok is False, T, T_init, covariance "
                              "and the sigmas are None and failure says why.")
      .def_property_readonly("ok", [](const PyTwoViewResult& p) { return p.r.ok; })
      .def_property_readonly("failure", [](const PyTwoViewResult& p) { return p.r.failure; })
      .def_property_readonly(
          "failure_rule", [](const PyTwoViewResult& p) { return p.r.failure_rule; },
          "the rule that refused the pose (inliers, inlier_ratio, chi2, ambiguous, local_fit, "
          "depth_inconsistent, degenerate, max_sigma) or ''")
      .def_property_readonly(
          "path", [](const PyTwoViewResult& p) { return p.r.path; },
          "which path produced T: 'features', 'depth-registration' or 'both'")
      .def_property_readonly(
          "fused", [](const PyTwoViewResult& p) { return p.r.fused; },
          "path 'both': T and covariance are the two paths' fusion (else the kept one's own)")
      .def_property_readonly(
          "detector", [](const PyTwoViewResult& p) { return p.r.detector; },
          "the features behind the pose: 'orb', or 'sift' when the SIFT retry found it")
      .def_property_readonly(
          "T", [](const PyTwoViewResult& p) { return poseOrNone(p, p.r.T_21); },
          "4x4 camera 2 from camera 1 (x2 = T @ x1), or None")
      .def_property_readonly(
          "T_init", [](const PyTwoViewResult& p) { return poseOrNone(p, p.r.T_init); },
          "the PnP pose before bundle adjustment, or None")
      .def_property_readonly(
          "covariance",
          [](const PyTwoViewResult& p) -> py::object {
            if (!p.r.ok || !p.r.covariance_ok) return py::none();
            return toNumpy(p.r.covariance);
          },
          "6x6: rotation xyz (rad), translation xyz (m); left perturbation of T, or None")
      .def_property_readonly(
          "information",
          [](const PyTwoViewResult& p) -> py::object {
            if (!p.r.ok || !p.r.covariance_ok) return py::none();
            // The covariance is symmetric positive definite when reported (covariance_ok).
            const Eigen::Matrix<double, 6, 6> info =
                p.r.covariance.ldlt().solve(Eigen::Matrix<double, 6, 6>::Identity());
            return toNumpy(Eigen::Matrix<double, 6, 6>(0.5 * (info + info.transpose())));
          },
          "6x6 inverse of covariance (a pose-graph edge's information, same order), or None")
      .def_property_readonly(
          "calibration_sensitivity",
          [](const PyTwoViewResult& p) -> py::object {
            if (!p.r.ok || !p.r.covariance_ok) return py::none();
            return toNumpy(p.r.calibration_sensitivity);
          },
          "6x5 pose shift per unit error of fx, fy (relative), cx, cy (px) and the depth scale "
          "(relative), rows in covariance's order: covariance's calibration term is "
          "S diag(sigma^2) S^T (and a focal margin on the rotation); edges of one camera share "
          "its error. Or None")
      .def_property_readonly(
          "sigma_deg",
          [](const PyTwoViewResult& p) -> py::object {
            if (!p.r.ok || !p.r.covariance_ok) return py::none();
            return py::cast(poseSigmas(p.r.covariance).deg);
          },
          "1-sigma rotation (sqrt of the trace of the rotation block), degrees")
      .def_property_readonly(
          "sigma_cm",
          [](const PyTwoViewResult& p) -> py::object {
            if (!p.r.ok || !p.r.covariance_ok) return py::none();
            return py::cast(poseSigmas(p.r.covariance).cm);
          },
          "1-sigma translation, centimetres")
      .def_property_readonly(
          "variance_factor",
          [](const PyTwoViewResult& p) -> py::object {
            if (!p.r.ok || !p.r.covariance_ok) return py::none();
            return py::cast(p.r.variance_factor);
          },
          "what the fit's pixel residuals scaled the pixel noise's variance by (1: not scaled)")
      .def_property_readonly(
          "depth_variance_factor",
          [](const PyTwoViewResult& p) -> py::object {
            if (!p.r.ok || !p.r.covariance_ok) return py::none();
            return py::cast(p.r.depth_variance_factor);
          },
          "what the fit's depth residuals scaled the depth noise's variance by (1: not scaled)")
      .def_property_readonly(
          "slide_sigma_m",
          [](const PyTwoViewResult& p) -> py::object {
            if (!p.r.ok || !p.r.covariance_ok || p.r.slide_sigma_m.isZero()) return py::none();
            return py::array_t<double>(3, p.r.slide_sigma_m.data());  // shape (3,), a copy
          },
          "the depth path's slide term: translation 1-sigma along camera 2's x, y, z (m, in "
          "covariance), or None where the returned pose is not the depth path's own")
      .def_property_readonly("inliers", [](const PyTwoViewResult& p) { return p.r.counts.inliers; })
      .def_property_readonly("counts",
                             [](const PyTwoViewResult& p) {
                               const TwoViewCounts& c = p.r.counts;
                               py::dict d;
                               d["keypoints1"] = c.keypoints1, d["keypoints2"] = c.keypoints2;
                               d["matches"] = c.matches, d["pairs"] = c.pairs;
                               d["inliers"] = c.inliers, d["rival_inliers"] = c.competitor_inliers;
                               d["depth_candidates"] = c.depth_candidates;
                               d["depth_duplicates"] = c.depth_duplicates;
                               return d;
                             })
      .def_property_readonly("timings_ms",
                             [](const PyTwoViewResult& p) {
                               const StageTimes& t = p.r.times_ms;
                               py::dict d;
                               for (const auto& [name, ms] : t.named()) d[name] = ms;
                               d["total"] = t.total_ms;
                               return d;
                             })
      .def_property_readonly("chi2_initial",
                             [](const PyTwoViewResult& p) { return p.r.chi2_initial; })
      .def_property_readonly("chi2_final", [](const PyTwoViewResult& p) { return p.r.chi2_final; })
      .def_property_readonly("ba_iterations",
                             [](const PyTwoViewResult& p) { return p.r.ba_iterations; })
      .def_property_readonly("solver", [](const PyTwoViewResult& p) { return p.r.solver; })
      .def_property_readonly("inlier_coverage",
                             [](const PyTwoViewResult& p) { return p.r.inlier_coverage; })
      .def_property_readonly(
          "depth_consistency",
          [](const PyTwoViewResult& p) { return measuredOrNone(p.r.depth_consistency); },
          "fraction of points whose depths agree in both images under T (None: not measured)")
      .def_property_readonly(
          "registration_fitness",
          [](const PyTwoViewResult& p) { return measuredOrNone(p.r.registration_fitness); },
          "the depth-only registration's fitness, when it ran")
      .def_property_readonly(
          "photometric_agreement",
          [](const PyTwoViewResult& p) {
            return p.r.photometric_agreement <= -1 ? py::none()
                                                   : py::cast(p.r.photometric_agreement);
          },
          "a depth-path pose's co-visible intensity correlation (None: not a depth-path pose)")
      .def_property_readonly(
          "overlap", [](const PyTwoViewResult& p) { return measuredOrNone(p.r.overlap); },
          "share of frame 1 a depth-path pose explains (None: not a depth-path pose)")
      .def_property_readonly(
          "keypoints1", [](const PyTwoViewResult& p) { return keypointArray(p.r.keypoints1); },
          "N1 x 2 pixel positions (x, y) in image 1")
      .def_property_readonly(
          "keypoints2", [](const PyTwoViewResult& p) { return keypointArray(p.r.keypoints2); },
          "N2 x 2 pixel positions in image 2")
      .def_property_readonly(
          "matches",
          [](const PyTwoViewResult& p) {
            return tableOf<int>(p.r.pairs.size(), 2, [&](size_t i, int k) {
              return k == 0 ? p.r.pairs[i].keypoint_1 : p.r.pairs[i].keypoint_2;
            });
          },
          "K x 2 keypoint indices (image 1, image 2) of each 3D-2D pair")
      .def_property_readonly(
          "points1",
          [](const PyTwoViewResult& p) {
            return tableOf<double>(p.r.pairs.size(), 3,
                                   [&](size_t i, int k) { return p.r.pairs[i].X_1[k]; });
          },
          "K x 3 points of the pairs in camera 1 (metres)")
      .def_property_readonly(
          "inlier_mask",
          [](const PyTwoViewResult& p) {
            return tableOf<bool>(p.r.inlier.size(), 0,
                                 [&](size_t i, int) { return p.r.inlier[i] != 0; });
          },
          "K booleans: pair i is a RANSAC and BA inlier")
      .def(
          "to_json", [](const PyTwoViewResult& p) { return twoViewReportJson(p.r, p.ba_mode); },
          "the JSON report pose_estimation_3d2d --json writes")
      .def("__repr__", [](const PyTwoViewResult& p) {
        if (!p.r.ok) return "TwoViewResult(ok=False, failure='" + p.r.failure + "')";
        return "TwoViewResult(ok=True, path='" + p.r.path +
               "', inliers=" + std::to_string(p.r.counts.inliers) + ")";
      });

  m.def(
      "estimate_two_view", &estimate, py::arg("image1"), py::arg("depth1"), py::arg("image2"),
      py::arg("depth2") = py::none(), py::kw_only(), py::arg("camera"),
      py::arg("features1") = py::none(), py::arg("features2") = py::none(),
      R"doc(Pose of camera 2 relative to camera 1 from an RGB-D frame and a colour (+ depth) frame.

Images as cv2.imread returns them: BGR (H, W, 3) or grey (H, W) uint8; depths (H, W) uint16
(cv2.IMREAD_UNCHANGED) in units of camera.depth_scale per metre, 0 or 65535 where there is none.
depth2 enables the depth consistency check and the depth-only path for texture-poor pairs.

Keyword options (the pose_estimation_3d2d options): preset ('textbook'), features (int),
max_feature_pixels (int: ORB on a copy of an image of more pixels, shrunk by a whole factor;
default 1280 * 960, 0 = every image at its own resolution), detector ('orb', 'sift', 'akaze'),
retry_with_sift (bool),
match_filter ('textbook', 'ratio', 'cross-check'), ransac_threshold (px), ba ('none', 'pose',
'textbook', 'two-camera', 'rgbd'), solver ('auto', 'native', 'ceres'), depth_path ('auto',
'off', 'always'), undistort (bool), max_sigma_deg, max_sigma_cm (float, 0 = off), and the
covariance model's focal_sigma, principal_point_sigma, depth_scale_sigma, motion_sigma,
motion_cap_deg, motion_cap_cm and fuse_agreeing (bool: a path 'both' pose is the two paths'
fusion); time_budget_ms (float, 0 = none: an optional stage that would not fit, or an
alignment that reaches it, refuses the pair, failure_rule 'time_budget').

features1, features2: the images' FrameFeatures from describe_frame, found once where a frame is
in several pairs (their detection is skipped; the answer is the same).

Raises ValueError (pnpba.Error) for bad images or options; returns a result with ok=False
when the pose cannot be estimated or is refused. The GIL is released while it runs.)doc");
  m.def(
      "check_two_view_options",
      [](const py::kwargs& kwargs) {
        std::string ba_mode;
        optionsFrom(kwargs, &ba_mode);
      },
      R"doc(Raises what estimate_two_view would for these keyword options (TypeError for an unknown
name, pnpba.Error for a bad value), without images: a batch checks its options once.)doc");
  m.def("preload_depth_registration", &preloadDepthRegistration,
        R"doc(Opens the depth registration's Open3D plugin now (25-90 ms, once per process) rather
than where a registration first takes one of Open3D's own steps. No option of estimate_two_view
does: its depth registration is pnpba's own and opens no plugin. Returns the milliseconds it took
(0.0 when already open); raises pnpba.Error when the plugin is missing.)doc");
}

}  // namespace pnpba::python
