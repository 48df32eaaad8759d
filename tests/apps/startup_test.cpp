// Start-up: no tool links Open3D or OpenCV's image codecs (together ~200 shared libraries and
// ~170 ms before main); they are plugins (pnpba/core/plugin.h) opened when a run needs them, and
// a PNG needs neither.
// Checked with the dynamic loader's own reports, not a clock.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "cli_runner.h"
#include "scratch_dir.h"

namespace {

namespace fs = std::filesystem;
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
  // Nor does the work each tool opens (its plugin, apps/common/tool_launcher.cpp).
  for (const char* work :
       {POSE_ESTIMATION_3D2D_WORK, EVALUATE_TUM_WORK, DIRECT_BA_WORK, RENDER_SYNTHETIC_WORK}) {
    const CliRun r = pnpba::test::runCli("ldd", work);
    ASSERT_EQ(r.exit_code, 0) << work << r.err;
    ASSERT_TRUE(mentions(r.out, "libopencv_core")) << work << ": " << r.out;
    EXPECT_FALSE(mentions(r.out, "libOpen3D")) << work;
    EXPECT_FALSE(mentions(r.out, "libopencv_imgcodecs")) << work;
    EXPECT_FALSE(mentions(r.out, "libgdal")) << work;
  }
}

TEST(Startup, HelpLoadsNoPlugin) {
  const CliRun r =
      pnpba::test::runCli("LD_DEBUG=files " + std::string(POSE_ESTIMATION_3D2D), "--help");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_FALSE(mentions(r.err, "libpnpba_")) << r.err;
}

// A tool's `--help` is the help the build kept from its parser (apps/common/tool_launcher.cpp):
// the same text as the parser prints, the program named as it was called, and none of the
// work's libraries loaded, where the parser's own help opens the tool's plugin and with it
// OpenCV or Ceres.
TEST(Startup, HelpIsTheParsersOwnWithoutTheWorksLibraries) {
  for (const char* tool : {POSE_ESTIMATION_3D2D, EVALUATE_TUM, DIRECT_BA, BUNDLE_ADJUST_PAIRS,
                           BUNDLE_ADJUST_BAL, BAL_SYNTHETIC, RENDER_SYNTHETIC}) {
    for (const char* flag : {"--help", "-h"}) {
      const CliRun kept = pnpba::test::runCli("LD_DEBUG=files " + std::string(tool), flag);
      const CliRun parsed =
          pnpba::test::runCli("PNPBA_TOOL_PARSE_HELP=1 LD_DEBUG=files " + std::string(tool), flag);
      ASSERT_EQ(kept.exit_code, 0) << tool << kept.err;
      ASSERT_EQ(parsed.exit_code, 0) << tool << parsed.err;
      EXPECT_TRUE(mentions(parsed.err, "libpnpba_tool_")) << tool << ": the parser did not run";
      EXPECT_TRUE(mentions(kept.out, std::string("Usage: ") + tool + " ")) << kept.out;
      EXPECT_EQ(kept.out, parsed.out) << tool << " " << flag;
      for (const char* library : {"libpnpba_", "libopencv_", "libceres", "libcholmod", "libtbb"}) {
        EXPECT_FALSE(mentions(kept.err, library)) << tool << " " << flag << " loads " << library;
      }
    }
  }
}

// pose_estimation_3d2d runs one pair and exits: where the kernel gives huge pages on request, its
// launcher starts it once more with glibc's heap on them (apps/common/tool_launcher.cpp), and
// leaves a GLIBC_TUNABLES that names the setting alone. The pose is the same either way.
TEST(Startup, TheOneJobToolsRestartOnceOnAHugePageHeap) {
  std::ifstream mode_file("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string mode;
  std::getline(mode_file, mode);
  const bool on_request = mode.find("[madvise]") != std::string::npos;
  const std::string pair = kImages + "1.png " + kImages + "2.png " + kImages + "1_depth.png " +
                           kImages + "2_depth.png --camera " + kImages + "camera.yaml";
  const auto starts = [](const std::string& loader_report) {
    int n = 0;
    for (size_t at = loader_report.find("transferring control"); at != std::string::npos;
         at = loader_report.find("transferring control", at + 1)) {
      ++n;
    }
    return n;
  };
  const CliRun own =
      pnpba::test::runCli("LD_DEBUG=files " + std::string(POSE_ESTIMATION_3D2D), pair);
  const CliRun kept = pnpba::test::runCli(
      "GLIBC_TUNABLES=glibc.malloc.hugetlb=0 LD_DEBUG=files " + std::string(POSE_ESTIMATION_3D2D),
      pair);
  ASSERT_EQ(own.exit_code, 0) << own.err;
  ASSERT_EQ(kept.exit_code, 0) << kept.err;
  EXPECT_EQ(starts(own.err), on_request ? 2 : 1) << mode;
  EXPECT_EQ(starts(kept.err), 1);
  // The pose and everything after it (the lines before include the BA's time).
  const auto pose = [](const std::string& out) {
    return out.substr(out.find("after optimization"));
  };
  ASSERT_NE(own.out.find("after optimization"), std::string::npos) << own.out;
  ASSERT_NE(kept.out.find("after optimization"), std::string::npos) << kept.out;
  EXPECT_EQ(pose(own.out), pose(kept.out));

  // bundle_adjust_bal runs one problem too; evaluate_tum runs a sequence in one process and
  // keeps the ordinary heap (a missing input: each exits at its parser).
  const CliRun bal =
      pnpba::test::runCli("LD_DEBUG=files " + std::string(BUNDLE_ADJUST_BAL), "/no/such/problem");
  const CliRun tum =
      pnpba::test::runCli("LD_DEBUG=files " + std::string(EVALUATE_TUM), "/no/such/sequence");
  EXPECT_NE(bal.exit_code, 0);
  EXPECT_NE(tum.exit_code, 0);
  EXPECT_EQ(starts(bal.err), on_request ? 2 : 1);
  EXPECT_EQ(starts(tum.err), 1);
}

// An installed tree the tools are run from by name (through PATH), wherever it was moved: the
// launcher finds its plugin in <prefix>/lib/pnpba beside <prefix>/bin, not in the build tree.
TEST(Startup, AToolRunThroughPathFindsThePluginOfItsOwnTree) {
  const fs::path prefix = pnpba::test::scratchPath("pnpba_moved_prefix");
  fs::create_directories(prefix / "bin");
  fs::create_directories(prefix / "lib" / "pnpba");
  const fs::path work = fs::path(RENDER_SYNTHETIC_WORK);
  fs::copy_file(RENDER_SYNTHETIC, prefix / "bin" / "render_synthetic");
  fs::copy_file(work, prefix / "lib" / "pnpba" / work.filename());
  const CliRun r = pnpba::test::runCli(
      "cd / && PATH=" + (prefix / "bin").string() + ":$PATH LD_DEBUG=files render_synthetic",
      "--output " + (prefix / "out").string() + " --no-such-option");
  fs::remove_all(prefix);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_TRUE(mentions(r.err, "no-such-option")) << r.err;  // the tool's own parser ran
  EXPECT_TRUE(mentions(r.err, "file=" + (prefix / "lib" / "pnpba" / work.filename()).string()))
      << r.err;
  EXPECT_FALSE(mentions(r.err, "file=" + work.string())) << "the build tree's plugin was opened";
}

// Anything else runs the tool's own parser, in the plugin: its errors and exit codes.
TEST(Startup, OtherArgumentsGoToTheToolsParser) {
  const CliRun r =
      pnpba::test::runCli(std::string(POSE_ESTIMATION_3D2D), "a.png b.png c.png --no-such-option");
  EXPECT_EQ(r.exit_code, 2) << r.out << r.err;
  EXPECT_TRUE(mentions(r.err, "no-such-option")) << r.err;
}

// PNG, the format of the pair here and of most RGB-D datasets, is decoded by libpng itself
// (imageio/src/png_decoding.h): a pair the features settle loads neither plugin.
TEST(Startup, PngPairTheFeaturesSettleLoadsNeitherTheCodecsNorOpen3d) {
  const CliRun r =
      pnpba::test::runCli("LD_DEBUG=files " + std::string(POSE_ESTIMATION_3D2D),
                          kImages + "1.png " + kImages + "2.png " + kImages + "1_depth.png " +
                              kImages + "2_depth.png --camera " + kImages + "camera.yaml");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_FALSE(mentions(r.err, "libpnpba_imgcodecs.so"));
  EXPECT_FALSE(mentions(r.err, "libopencv_imgcodecs"));
  EXPECT_FALSE(mentions(r.err, "libpnpba_open3d.so"));
  EXPECT_FALSE(mentions(r.err, "libOpen3D"));
}

// Another format goes to OpenCV's codecs, opened then, and gives the same pose as its PNG
// (a lossless format: the same pixels).
TEST(Startup, OtherFormatsOpenTheCodecsAndGiveTheSamePose) {
  const fs::path dir = pnpba::test::scratchPath("pnpba_startup");
  fs::create_directories(dir);
  for (const char* name : {"1", "2"}) {
    const cv::Mat image = cv::imread(kImages + name + ".png", cv::IMREAD_UNCHANGED);
    ASSERT_TRUE(cv::imwrite((dir / (std::string(name) + ".bmp")).string(), image));
  }
  const std::string rest =
      kImages + "1_depth.png " + kImages + "2_depth.png --camera " + kImages + "camera.yaml";
  const CliRun png = pnpba::test::runCli(std::string(POSE_ESTIMATION_3D2D),
                                         kImages + "1.png " + kImages + "2.png " + rest);
  const CliRun bmp =
      pnpba::test::runCli("LD_DEBUG=files " + std::string(POSE_ESTIMATION_3D2D),
                          (dir / "1.bmp").string() + " " + (dir / "2.bmp").string() + " " + rest);
  fs::remove_all(dir);
  ASSERT_EQ(png.exit_code, 0) << png.err;
  ASSERT_EQ(bmp.exit_code, 0) << bmp.err;
  EXPECT_TRUE(mentions(bmp.err, "libpnpba_imgcodecs.so"));
  const auto pose = [](const std::string& out) { return out.substr(out.find("T=")); };
  ASSERT_NE(png.out.find("T="), std::string::npos) << png.out;
  ASSERT_NE(bmp.out.find("T="), std::string::npos) << bmp.out;
  EXPECT_EQ(pose(bmp.out).substr(0, 200), pose(png.out).substr(0, 200));
}

}  // namespace
