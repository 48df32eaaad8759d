// Estimates the pose of an RGB-D pair with an installed pnpba and prints T as 16 numbers.
#include <cstdio>
#include <exception>

#include "pnpba/pipeline/camera.h"
#include "pnpba/pipeline/image_files.h"
#include "pnpba/pipeline/two_view.h"

int main(int argc, char** argv) {
  if (argc != 6) {
    std::fprintf(stderr, "usage: two_view_consumer img1 img2 depth1 depth2 camera.yaml\n");
    return 2;
  }
  try {
    const pnpba::Camera camera = pnpba::loadCameraYaml(argv[5]);
    const pnpba::TwoViewResult r =
        pnpba::estimateTwoView(pnpba::readColourImage(argv[1]), pnpba::readDepthImage(argv[3]),
                               pnpba::readColourImage(argv[2]), pnpba::readDepthImage(argv[4]),
                               camera, pnpba::TwoViewOptions{});
    if (!r.ok) {
      std::fprintf(stderr, "no pose: %s\n", r.failure.c_str());
      return 1;
    }
    const Eigen::Matrix4d T = r.T_21.to_homogeneous_matrix();
    for (int i = 0; i < 16; ++i) std::printf("%.17g\n", T(i / 4, i % 4));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  }
  return 0;
}
