// Start-up: no tool links Open3D or OpenCV's image codecs (together ~200 shared libraries and
// ~170 ms before main); they are plugins (pnpba/core/plugin.h) opened when a run needs them.
// Checked with the dynamic loader's own reports, not a clock.
#include <gtest/gtest.h>

#include <string>

#include "cli_runner.h"

namespace {

using pnpba::test::CliRun;

const std::string kImages = std::string(PNPBA_SOURCE_DIR) + "/data/images/";

bool mentions(const std::string& text, const std::string& library) {
  return text.find(library) != std::string::npos;
}

TEST(Startup, NoToolLinksOpen3dOrTheImageCodecs) {
  for (const char* tool : {POSE_ESTIMATION_3D2D, EVALUATE_TUM, DIRECT_BA, BUNDLE_ADJUST_PAIRS,
                           BUNDLE_ADJUST_BAL, BAL_SYNTHETIC, RENDER_SYNTHETIC}) {
    // LD_TRACE_LOADED_OBJECTS: the loader lists what the program links and exits (ldd's way).
    const CliRun r = pnpba::test::runCli("LD_TRACE_LOADED_OBJECTS=1 " + std::string(tool), "");
    ASSERT_EQ(r.exit_code, 0) << tool << r.err;
    ASSERT_TRUE(mentions(r.out, "libc.so")) << tool << ": " << r.out;
    EXPECT_FALSE(mentions(r.out, "libOpen3D")) << tool;
    EXPECT_FALSE(mentions(r.out, "libopencv_imgcodecs")) << tool;
    EXPECT_FALSE(mentions(r.out, "libgdal")) << tool;
  }
}

TEST(Startup, HelpLoadsNoPlugin) {
  const CliRun r =
      pnpba::test::runCli("LD_DEBUG=files " + std::string(POSE_ESTIMATION_3D2D), "--help");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_FALSE(mentions(r.err, "libpnpba_")) << r.err;
}

TEST(Startup, PairTheFeaturesSettleLoadsTheCodecsButNotOpen3d) {
  const CliRun r =
      pnpba::test::runCli("LD_DEBUG=files " + std::string(POSE_ESTIMATION_3D2D),
                          kImages + "1.png " + kImages + "2.png " + kImages + "1_depth.png " +
                              kImages + "2_depth.png --camera " + kImages + "camera.yaml");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(mentions(r.err, "libpnpba_imgcodecs.so"));
  EXPECT_FALSE(mentions(r.err, "libpnpba_open3d.so"));
  EXPECT_FALSE(mentions(r.err, "libOpen3D"));
}

}  // namespace
