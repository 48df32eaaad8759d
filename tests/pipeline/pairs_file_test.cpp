// The pair-file reader: exact values on a good file, "<path>:<line>: <problem>" on bad ones.
#include "pnpba/pipeline/pairs_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "pnpba/core/error.h"
#include "scratch_dir.h"

namespace pnpba {
namespace {

std::string writeTemp(const std::string& name, const std::string& text) {
  const auto path = pnpba::test::scratchDir() / ("pnpba_pairs_" + name);
  std::ofstream(path) << text;
  return path.string();
}

std::string errorOf(const std::string& path) {
  try {
    readPairsFile(path);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(PairsFile, ReadsFiveAndSevenColumnFiles) {
  const auto seven =
      readPairsFile(writeTemp("7", "# comment\n1 2 3 4 5 6 7\n\n0.5 -1 2 10 20 30 40 # x\n"));
  ASSERT_EQ(seven.pairs.size(), 2u);
  EXPECT_TRUE(seven.has_image1_pixels);
  EXPECT_EQ(seven.pairs[1].X_1, Eigen::Vector3d(0.5, -1, 2));
  EXPECT_EQ(seven.pairs[1].uv_2, Eigen::Vector2d(10, 20));
  EXPECT_EQ(seven.pairs[1].uv_1, Eigen::Vector2d(30, 40));
  const auto five = readPairsFile(writeTemp("5", "1 2 3 4 5\n"));
  EXPECT_FALSE(five.has_image1_pixels);
}

TEST(PairsFile, MalformedFilesNameFileAndLine) {
  const std::string bad_count = writeTemp("count", "1 2 3 4 5\n1 2 3 4\n");
  EXPECT_EQ(errorOf(bad_count),
            bad_count + ":2: expected 5 (X Y Z u2 v2) or 7 (... u1 v1) numbers, got 4");
  const std::string nan = writeTemp("nan", "1 2 nan 4 5\n");
  EXPECT_EQ(errorOf(nan), nan + ":1: non-finite value 'nan'");
  const std::string text = writeTemp("text", "1 2 3 4 x5\n");
  EXPECT_EQ(errorOf(text), text + ":1: 'x5' is not a number");
  const std::string mixed = writeTemp("mixed", "1 2 3 4 5\n1 2 3 4 5 6 7\n");
  EXPECT_EQ(errorOf(mixed), mixed + ":2: has 7 numbers, earlier lines 5");
  const std::string depth = writeTemp("depth", "1 2 0 4 5\n");
  EXPECT_EQ(errorOf(depth), depth + ":1: depth Z must be > 0");
  const std::string empty = writeTemp("empty", "");
  EXPECT_EQ(errorOf(empty), empty + ": no pairs in file");
  EXPECT_EQ(errorOf("/nonexistent/pairs.txt"), "/nonexistent/pairs.txt: cannot open file");
}

}  // namespace
}  // namespace pnpba
