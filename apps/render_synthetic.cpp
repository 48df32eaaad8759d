// render_synthetic: renders pnpba's synthetic RGB-D pair with exact ground truth into a
// folder: 1.png, 2.png (colour), 1_depth.png, 2_depth.png (16-bit, x5000, noise and holes),
// camera.yaml (ORB-SLAM2 style) and T_21.txt (the true 4x4 T_21, row-major).
//
//   render_synthetic --output data/images [--seed 7] [--distortion k1,k2,p1,p2,k3]
#include <CLI/CLI.hpp>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <opencv2/imgcodecs.hpp>

#include "atomic_write.h"
#include "cli_values.h"
#include "pnpba/core/error.h"
#include "pnpba/synthetic/synthetic_scene.h"

namespace {

void writePng(const std::string& path, const cv::Mat& image) {
  std::vector<uchar> png;
  if (!cv::imencode(".png", image, png)) throw pnpba::Error(path + ": PNG encoding failed");
  pnpba::writeFileAtomically(path, [&png](std::ostream& out) {
    out.write(reinterpret_cast<const char*>(png.data()), static_cast<std::streamsize>(png.size()));
  });
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Render pnpba's synthetic two-view RGB-D scene with its ground-truth T_21."};
  std::string output, distortion_text;
  unsigned seed = 7;
  app.add_option("--output", output, "folder to write into (created if missing)")->required();
  app.add_option("--seed", seed, "scene and noise seed")->capture_default_str();
  app.add_option("--distortion", distortion_text, "k1,k2,p1,p2,k3 applied to both images");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  try {
    pnpba::SyntheticCamera camera;
    if (!distortion_text.empty()) {
      const auto d = pnpba::parseNumberList(distortion_text, 5, "--distortion");
      std::copy(d.begin(), d.end(), camera.pinhole.distortion.begin());
    }
    std::error_code ec;
    std::filesystem::create_directories(output, ec);
    if (ec) throw pnpba::Error(output + ": cannot create folder (" + ec.message() + ")");

    const pnpba::SyntheticScene scene(seed);
    const pnpba::SE3Quat T_21 = pnpba::SyntheticScene::defaultMotion();
    const pnpba::DepthNoise noise;
    const pnpba::RenderedView v1 = scene.render(camera, pnpba::SE3Quat(), noise, seed + 1);
    const pnpba::RenderedView v2 = scene.render(camera, T_21, noise, seed + 2);
    writePng(output + "/1.png", v1.colour);
    writePng(output + "/2.png", v2.colour);
    writePng(output + "/1_depth.png", v1.depth);
    writePng(output + "/2_depth.png", v2.depth);
    const pnpba::PinholeCamera& k = camera.pinhole;
    pnpba::writeFileAtomically(output + "/camera.yaml", [&](std::ostream& out) {
      out << std::setprecision(10) << "%YAML:1.0\n# pnpba synthetic scene camera\n"
          << "Camera.fx: " << k.fx << "\nCamera.fy: " << k.fy << "\nCamera.cx: " << k.cx
          << "\nCamera.cy: " << k.cy << "\nCamera.k1: " << k.distortion[0]
          << "\nCamera.k2: " << k.distortion[1] << "\nCamera.p1: " << k.distortion[2]
          << "\nCamera.p2: " << k.distortion[3] << "\nCamera.k3: " << k.distortion[4]
          << "\nCamera.width: " << camera.width << "\nCamera.height: " << camera.height
          << "\nDepthMapFactor: " << camera.depth_scale << "\n";
    });
    pnpba::writeFileAtomically(output + "/T_21.txt", [&](std::ostream& out) {
      out << "# ground truth T_21 (camera 2 from camera 1), row-major 4x4\n"
          << std::setprecision(17) << T_21.to_homogeneous_matrix() << "\n";
    });
    std::cout << "wrote " << output << "/{1,2}.png, {1,2}_depth.png, camera.yaml, T_21.txt\n";
    return 0;
  } catch (const pnpba::Error& e) {
    std::cerr << "render_synthetic: " << e.what() << "\n";
    return 2;
  }
}
