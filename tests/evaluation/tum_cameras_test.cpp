// Which TUM camera a folder gets: the names the benchmark's folders carry, the rule's order
// (--camera, FOLDER/camera.yaml, the path's name, freiburg1 assumed), and the built-in
// calibrations against the YAML files the project ships.
#include "pnpba/evaluation/tum_cameras.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "pnpba/core/error.h"
#include "scratch_dir.h"
#include "shared_data.h"

namespace pnpba {
namespace {

namespace fs = std::filesystem;

std::string shippedCamera(const std::string& name) {
  return std::string(PNPBA_SOURCE_DIR) + "/data/cameras/" + name;
}

void expectSameCamera(const Camera& a, const Camera& b) {
  EXPECT_EQ(a.pinhole.fx, b.pinhole.fx);
  EXPECT_EQ(a.pinhole.fy, b.pinhole.fy);
  EXPECT_EQ(a.pinhole.cx, b.pinhole.cx);
  EXPECT_EQ(a.pinhole.cy, b.pinhole.cy);
  ASSERT_EQ(a.pinhole.distortion.size(), b.pinhole.distortion.size());
  for (size_t i = 0; i < a.pinhole.distortion.size(); ++i) {
    EXPECT_EQ(a.pinhole.distortion[i], b.pinhole.distortion[i]) << i;
  }
  EXPECT_EQ(a.depth_scale, b.depth_scale);
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
}

// A folder in the process's scratch folder, made afresh (removed first).
fs::path freshFolder(const std::string& relative) {
  const fs::path root = pnpba::test::scratchDir() / "pnpba_tum_cameras";
  const fs::path p = root / relative;
  fs::remove_all(p);
  fs::create_directories(p);
  return p;
}

TEST(TumCameras, BuiltInCalibrationsAreTheShippedYamlFiles) {
  expectSameCamera(tumFreiburgCamera(1), loadCameraYaml(shippedCamera("tum_fr1.yaml")));
  expectSameCamera(tumFreiburgCamera(2), loadCameraYaml(shippedCamera("tum_fr2.yaml")));
  expectSameCamera(tumFreiburgCamera(3), loadCameraYaml(shippedCamera("tum_fr3.yaml")));
  expectSameCamera(tumFreiburg1Camera(), tumFreiburgCamera(1));
  EXPECT_THROW(tumFreiburgCamera(4), Error);
  EXPECT_THROW(tumFreiburgCamera(0), Error);
}

TEST(TumCameras, TheBenchmarksFolderNamesNameTheirCamera) {
  EXPECT_EQ(tumFreiburgNamedBy("/data/rgbd_dataset_freiburg3_cabinet"), 3);
  EXPECT_EQ(tumFreiburgNamedBy("/data/rgbd_dataset_freiburg2_xyz/"), 2);  // trailing separator
  EXPECT_EQ(tumFreiburgNamedBy("/data/rgbd_dataset_freiburg1_desk"), 1);
  EXPECT_EQ(tumFreiburgNamedBy("../shared/data/tum_fr3_cabinet_keyframes"), 3);
  EXPECT_EQ(tumFreiburgNamedBy("/data/TUM-FR2/pioneer_360"), 2);  // a parent's name, any case
  // The innermost name decides: a fr3 sequence unpacked under a folder called fr2.
  EXPECT_EQ(tumFreiburgNamedBy("/data/fr2/rgbd_dataset_freiburg3_long_office"), 3);
}

TEST(TumCameras, NamesThatOnlyLookLikeACameraNameNone) {
  EXPECT_EQ(tumFreiburgNamedBy("/data/frames"), 0);
  EXPECT_EQ(tumFreiburgNamedBy("/data/fr12_test"), 0);       // not 1 to 3 alone
  EXPECT_EQ(tumFreiburgNamedBy("/data/afr3/seq"), 0);        // part of a word
  EXPECT_EQ(tumFreiburgNamedBy("/data/freiburg4_x"), 0);     // no such camera
  EXPECT_EQ(tumFreiburgNamedBy("/data/fr1_vs_fr2/seq"), 0);  // two cameras: no guess
  EXPECT_EQ(tumFreiburgNamedBy(""), 0);
}

TEST(TumCameras, TheRulesOrderIsCameraThenFolderYamlThenNameThenFreiburg1) {
  const fs::path named = freshFolder("rgbd_dataset_freiburg2_xyz");
  SequenceCamera c = sequenceCamera(named.string(), "");
  EXPECT_EQ(c.freiburg, 2);
  EXPECT_FALSE(c.assumed);
  EXPECT_EQ(c.source, "TUM freiburg2 (named by the folder)");
  expectSameCamera(c.camera, tumFreiburgCamera(2));

  // The folder's own camera.yaml outranks its name ...
  fs::copy_file(shippedCamera("tum_fr3.yaml"), named / "camera.yaml");
  c = sequenceCamera(named.string(), "");
  EXPECT_EQ(c.freiburg, 0);
  EXPECT_EQ(c.source, (named / "camera.yaml").string());
  expectSameCamera(c.camera, tumFreiburgCamera(3));
  // ... and --camera outranks both.
  c = sequenceCamera(named.string(), shippedCamera("tum_fr1.yaml"));
  EXPECT_EQ(c.source, shippedCamera("tum_fr1.yaml"));
  expectSameCamera(c.camera, tumFreiburgCamera(1));

  const fs::path plain = freshFolder("my_sequence");
  c = sequenceCamera(plain.string(), "");
  EXPECT_TRUE(c.assumed);
  EXPECT_EQ(c.freiburg, 1);
  EXPECT_NE(c.source.find("TUM freiburg1 (assumed"), std::string::npos) << c.source;
  EXPECT_NE(c.source.find("--camera"), std::string::npos) << c.source;

  EXPECT_THROW(sequenceCamera(plain.string(), (plain / "missing.yaml").string()), Error);
}

TEST(TumCameras, TheSharedCabinetKeyFramesGetFreiburg3) {
  PNPBA_REQUIRE_SHARED_DATA();
  const SequenceCamera c = sequenceCamera(test::sharedData("tum_fr3_cabinet_keyframes"), "");
  EXPECT_EQ(c.freiburg, 3);
  expectSameCamera(c.camera, loadCameraYaml(shippedCamera("tum_fr3.yaml")));
  EXPECT_EQ(sequenceCamera(test::sharedData("tum_fr1_desk"), "").freiburg, 1);
}

}  // namespace
}  // namespace pnpba
