// render_synthetic: renders pnpba's synthetic RGB-D pair with exact ground truth into a
// folder: 1.png, 2.png (colour), 1_depth.png, 2_depth.png (16-bit, x5000, noise and holes),
// camera.yaml (ORB-SLAM2 style) and T_21.txt (the true 4x4 T_21, row-major).
//
//   render_synthetic --output data/images [--seed 7] [--distortion k1,k2,p1,p2,k3]
#include <CLI/CLI.hpp>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <opencv2/imgcodecs.hpp>  // the flags; the codecs come through pnpba::imageio

#include "cli_values.h"
#include "pnpba/core/error.h"
#include "pnpba/core/output_file.h"
#include "pnpba/imageio/image_codec.h"
#include "pnpba/synthetic/synthetic_pair.h"
#include "tool_entry.h"

namespace {

void writePng(const std::string& path, const cv::Mat& image) {
  std::vector<uchar> png;
  if (!pnpba::encodeImage(".png", image, &png)) throw pnpba::Error(path + ": PNG encoding failed");
  pnpba::writeOutputFile(path, [&png](std::ostream& out) {
    out.write(reinterpret_cast<const char*>(png.data()), static_cast<std::streamsize>(png.size()));
  });
}

}  // namespace

PNPBA_TOOL_MAIN(int argc, char** argv) {
  CLI::App app{"Render pnpba's synthetic two-view RGB-D scene with its ground-truth T_21."};
  std::string output, distortion_text, scene_name = "sample", texture_name = "rich",
                                       axis_text = "0,1,0";
  pnpba::SyntheticPairOptions options;
  double rotation_deg = 0, translation_m = 0;
  bool flip_y = false;
  app.add_option("--output", output, "folder to write into (created if missing)")->required();
  app.add_option("--seed", options.seed, "scene and noise seed")->capture_default_str();
  app.add_option("--scene", scene_name,
                 "sample (the open room of data/images), room (a closed room for wide "
                 "baselines), cabinet (a plain cabinet by a wall), structure (a plain zig-zag "
                 "of panels on a floor), corridor (a plain wall on a plain floor, both running "
                 "along x) or poster (a poster on a plain wall, one plane)")
      ->capture_default_str();
  app.add_option(
         "--texture", texture_name,
         "rich, poor (plain surfaces, one poster) or tiled (rich cut to a 0.5 m tile, repeated)")
      ->capture_default_str();
  app.add_option("--rotation-deg", rotation_deg,
                 "camera 2 turned by this about --axis (with --translation-m; default: the "
                 "sample's 3 deg, 12 cm)");
  app.add_option("--axis", axis_text, "rotation axis x,y,z in camera 1 (y points down)")
      ->capture_default_str();
  app.add_option("--translation-m", translation_m,
                 "camera 2's centre this far from camera 1's, placed to keep looking at the "
                 "point 3 m ahead");
  app.add_option("--distortion", distortion_text, "k1,k2,p1,p2,k3 applied to both images");
  app.add_option("--depth-scale", options.camera.depth_scale, "depth units per metre")
      ->capture_default_str();
  app.add_option("--depth-noise", options.noise.noise_k, "k of sigma_z = k z^2 (1/m)")
      ->capture_default_str();
  app.add_option("--holes", options.noise.hole_fraction, "fraction of depth pixels dropped")
      ->capture_default_str();
  app.add_flag("--flip-y", flip_y, "negative fy (y-up image rows, as ICL-NUIM)");
  bool kinect = false;
  app.add_flag("--kinect", kinect,
               "Kinect-like sensor: disparity-quantised depth, holes at depth edges, depth 2 px "
               "off the colour, JPEG colour (quality 75)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  try {
    pnpba::SyntheticCamera& camera = options.camera;
    if (!distortion_text.empty()) {
      const auto d = pnpba::parseNumberList(distortion_text, 5, "--distortion");
      std::copy(d.begin(), d.end(), camera.pinhole.distortion.begin());
    }
    if (flip_y) camera.pinhole.fy = -camera.pinhole.fy;
    if (scene_name != "sample" && scene_name != "room" && scene_name != "cabinet" &&
        scene_name != "structure" && scene_name != "corridor" && scene_name != "poster") {
      throw pnpba::Error("--scene: unknown scene '" + scene_name +
                         "' (sample, room, cabinet, structure, corridor, poster)");
    }
    if (kinect) options.sensor = pnpba::SensorEffects::kinectLike();
    if (texture_name != "rich" && texture_name != "poor" && texture_name != "tiled") {
      throw pnpba::Error("--texture: unknown texture '" + texture_name + "' (rich, poor, tiled)");
    }
    options.layout = scene_name == "room"        ? pnpba::SceneLayout::kClosedRoom
                     : scene_name == "cabinet"   ? pnpba::SceneLayout::kCabinet
                     : scene_name == "structure" ? pnpba::SceneLayout::kStructure
                     : scene_name == "corridor"  ? pnpba::SceneLayout::kCorridor
                     : scene_name == "poster"    ? pnpba::SceneLayout::kPoster
                                                 : pnpba::SceneLayout::kOpenRoom;
    options.texture = texture_name == "poor"    ? pnpba::SceneTexture::kPoor
                      : texture_name == "tiled" ? pnpba::SceneTexture::kTiled
                                                : pnpba::SceneTexture::kRich;
    if (app.count("--rotation-deg") || app.count("--translation-m")) {
      const auto a = pnpba::parseNumberList(axis_text, 3, "--axis");
      const Eigen::Vector3d axis(a[0], a[1], a[2]);
      if (!(axis.norm() > 0)) throw pnpba::Error("--axis must not be zero");
      if (!(translation_m >= 0)) throw pnpba::Error("--translation-m must be >= 0");
      options.T_21 = pnpba::SyntheticScene::lookAtMotion(rotation_deg, axis, translation_m);
    }
    const std::string problem = options.validate();
    if (!problem.empty()) throw pnpba::Error(problem);
    std::error_code ec;
    std::filesystem::create_directories(output, ec);
    if (ec) throw pnpba::Error(output + ": cannot create folder (" + ec.message() + ")");

    const pnpba::SyntheticPair pair = pnpba::renderSyntheticPair(options);
    writePng(output + "/1.png", pair.view1.colour);
    writePng(output + "/2.png", pair.view2.colour);
    writePng(output + "/1_depth.png", pair.view1.depth);
    writePng(output + "/2_depth.png", pair.view2.depth);
    const pnpba::PinholeCamera& k = camera.pinhole;
    pnpba::writeOutputFile(output + "/camera.yaml", [&](std::ostream& out) {
      out << std::setprecision(10) << "%YAML:1.0\n# pnpba synthetic scene camera\n"
          << "Camera.fx: " << k.fx << "\nCamera.fy: " << k.fy << "\nCamera.cx: " << k.cx
          << "\nCamera.cy: " << k.cy << "\nCamera.k1: " << k.distortion[0]
          << "\nCamera.k2: " << k.distortion[1] << "\nCamera.p1: " << k.distortion[2]
          << "\nCamera.p2: " << k.distortion[3] << "\nCamera.k3: " << k.distortion[4]
          << "\nCamera.width: " << camera.width << "\nCamera.height: " << camera.height
          << "\nDepthMapFactor: " << camera.depth_scale << "\n";
    });
    pnpba::writeOutputFile(output + "/T_21.txt", [&](std::ostream& out) {
      out << "# ground truth T_21 (camera 2 from camera 1), row-major 4x4\n"
          << std::setprecision(17) << pair.T_21.to_homogeneous_matrix() << "\n";
    });
    std::cout << "wrote " << output << "/{1,2}.png, {1,2}_depth.png, camera.yaml, T_21.txt\n";
    return 0;
  } catch (const pnpba::Error& e) {
    std::cerr << "render_synthetic: " << e.what() << "\n";
    return 2;
  }
}
