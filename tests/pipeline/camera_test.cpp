// Camera YAML loading: ORB-SLAM2 settings read exactly; malformed files name file and line.
#include "pnpba/pipeline/camera.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "pnpba/core/error.h"
#include "scratch_dir.h"

namespace pnpba {
namespace {

std::string writeTemp(const std::string& name, const std::string& text) {
  const auto path = pnpba::test::scratchDir() / ("pnpba_camera_" + name);
  std::ofstream(path) << text;
  return path.string();
}

std::string errorOf(const std::string& path) {
  try {
    loadCameraYaml(path);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(CameraYaml, ReadsOrbSlam2Settings) {
  const Camera c = loadCameraYaml(writeTemp("good.yaml",
                                            "%YAML:1.0\n"
                                            "Camera.type: \"PinHole\"\n"
                                            "Camera.fx: 517.3\nCamera.fy: 516.5\n"
                                            "Camera.cx: 318.6  # centre\nCamera.cy: 255.3\n"
                                            "Camera.k1: 0.2624\nCamera.k2: -0.9531\n"
                                            "Camera.p1: -0.0054\nCamera.p2: 0.0026\n"
                                            "Camera.k3: 1.1633\nCamera.width: 640\n"
                                            "Camera.height: 480\nDepthMapFactor: 5000.0\n"
                                            "ORBextractor.nFeatures: 1000\n"));
  EXPECT_DOUBLE_EQ(c.pinhole.fx, 517.3);
  EXPECT_DOUBLE_EQ(c.pinhole.cy, 255.3);
  EXPECT_DOUBLE_EQ(c.pinhole.distortion[4], 1.1633);
  EXPECT_EQ(c.width, 640);
  EXPECT_DOUBLE_EQ(c.depth_scale, 5000.0);
}

TEST(CameraYaml, MalformedFilesAreNamed) {
  const std::string text = writeTemp("text.yaml", "Camera.fx: abc\n");
  EXPECT_EQ(errorOf(text), text + ":1: Camera.fx: 'abc' is not a number");
  const std::string missing = writeTemp("missing.yaml", "Camera.fx: 500\nCamera.fy: 500\n");
  EXPECT_EQ(errorOf(missing), missing + ": missing Camera.cx");
  const std::string syntax = writeTemp("syntax.yaml", "Camera.fx 500\n");
  EXPECT_EQ(errorOf(syntax), syntax + ":1: expected 'key: value'");
  const std::string negative =
      writeTemp("negative.yaml", "Camera.fx: -5\nCamera.fy: 500\nCamera.cx: 1\nCamera.cy: 1\n");
  EXPECT_EQ(errorOf(negative), negative + ": fx must be finite and > 0");
  EXPECT_EQ(errorOf("/nonexistent.yaml"), "/nonexistent.yaml: cannot open file");
}

// Found by scripts/fuzz.sh: a size beyond int was cast (undefined behaviour), not refused.
TEST(CameraYaml, ImageSizesMustBeWholePixelCounts) {
  const std::string head = "Camera.fx: 500\nCamera.fy: 500\nCamera.cx: 1\nCamera.cy: 1\n";
  const std::string huge = writeTemp("huge.yaml", head + "Camera.height: 4802222222\n");
  EXPECT_EQ(errorOf(huge), huge + ": Camera.height must be a whole number of pixels in 0..1000000");
  const std::string half = writeTemp("half.yaml", head + "Camera.width: 640.5\n");
  EXPECT_EQ(errorOf(half), half + ": Camera.width must be a whole number of pixels in 0..1000000");
  const std::string negative = writeTemp("negsize.yaml", head + "Camera.width: -1\n");
  EXPECT_NE(errorOf(negative), "");
}

}  // namespace
}  // namespace pnpba
