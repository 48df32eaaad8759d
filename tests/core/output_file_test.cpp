// Output files never damage what their path points at: each kind of target by the rule of
// core/include/pnpba/core/output_file.h, checked against the file system directly.
#include "pnpba/core/output_file.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "pnpba/core/error.h"
#include "scratch_dir.h"

namespace pnpba {
namespace {

namespace fs = std::filesystem;

class OutputFile : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ =
        pnpba::test::scratchPath(::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    fs::permissions(dir_, fs::perms::owner_all);
    fs::remove_all(dir_);
  }
  static std::string slurp(const fs::path& p) {
    std::ifstream in(p);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }
  static void write(const fs::path& p, const std::string& text) {
    writeOutputFile(p.string(), [&text](std::ostream& o) { o << text; });
  }
  // Only the files the test made: no temporary left behind.
  size_t entries() const {
    return static_cast<size_t>(
        std::distance(fs::directory_iterator(dir_), fs::directory_iterator()));
  }
  fs::path dir_;
};

TEST_F(OutputFile, NewPathIsCreatedWithUmaskPermissions) {
  write(dir_ / "new.json", "{}\n");
  EXPECT_EQ(slurp(dir_ / "new.json"), "{}\n");
  EXPECT_EQ(entries(), 1u);
  const mode_t mask = umask(0);
  umask(mask);
  EXPECT_EQ(fs::status(dir_ / "new.json").permissions(), static_cast<fs::perms>(0666 & ~mask));
}

TEST_F(OutputFile, RegularFileIsReplacedKeepingItsPermissions) {
  write(dir_ / "a.txt", "old");
  fs::permissions(dir_ / "a.txt",
                  fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);
  write(dir_ / "a.txt", "new");
  EXPECT_EQ(slurp(dir_ / "a.txt"), "new");
  EXPECT_EQ(fs::status(dir_ / "a.txt").permissions(),
            fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);
  EXPECT_EQ(entries(), 1u);
}

TEST_F(OutputFile, FailingProducerLeavesThePreviousFileAndNoTemporary) {
  write(dir_ / "keep.txt", "previous");
  EXPECT_THROW(writeOutputFile((dir_ / "keep.txt").string(),
                               [](std::ostream& o) {
                                 o << "half";
                                 throw Error("producer failed");
                               }),
               Error);
  EXPECT_EQ(slurp(dir_ / "keep.txt"), "previous");
  EXPECT_EQ(entries(), 1u);
}

TEST_F(OutputFile, SymlinkStaysALinkAndItsTargetIsWritten) {
  write(dir_ / "target.json", "old");
  fs::create_symlink("target.json", dir_ / "link.json");
  write(dir_ / "link.json", "new");
  EXPECT_TRUE(fs::is_symlink(dir_ / "link.json"));
  EXPECT_EQ(slurp(dir_ / "target.json"), "new");
  EXPECT_EQ(entries(), 2u);
}

TEST_F(OutputFile, DanglingSymlinkCreatesItsTarget) {
  fs::create_directories(dir_ / "shared");
  fs::create_symlink(dir_ / "shared" / "result.json", dir_ / "result.json");
  write(dir_ / "result.json", "made");
  EXPECT_TRUE(fs::is_symlink(dir_ / "result.json"));
  EXPECT_EQ(slurp(dir_ / "shared" / "result.json"), "made");
}

TEST_F(OutputFile, FifoIsWrittenIntoNeverReplaced) {
  const fs::path fifo = dir_ / "pipe";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  std::string received;
  std::thread reader([&] { received = slurp(fifo); });
  write(fifo, "through the pipe\n");
  reader.join();
  EXPECT_EQ(received, "through the pipe\n");
  EXPECT_TRUE(fs::is_fifo(fifo));
}

TEST_F(OutputFile, FullDeviceIsAnErrorAndStaysADevice) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full here";
  try {
    write("/dev/full", std::string(1 << 16, 'x'));
    FAIL() << "writing to /dev/full succeeded";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("/dev/full: write failed (No space left on device)"),
              std::string::npos)
        << e.what();
  }
  EXPECT_TRUE(fs::is_character_file("/dev/full"));
}

TEST_F(OutputFile, FolderAndMissingFolderAreErrorsUpFront) {
  EXPECT_THROW(checkOutputPath(dir_.string()), Error);
  EXPECT_THROW(write(dir_, "x"), Error);
  try {
    checkOutputPath((dir_ / "missing" / "out.json").string());
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("folder does not exist"), std::string::npos);
  }
  EXPECT_NO_THROW(checkOutputPath((dir_ / "fine.json").string()));
  EXPECT_NO_THROW(checkOutputPath("/dev/null"));
}

TEST_F(OutputFile, ReadOnlyFolderIsAnErrorWhenNotRoot) {
  if (geteuid() == 0) GTEST_SKIP() << "root writes into read-only folders";
  fs::permissions(dir_, fs::perms::owner_read | fs::perms::owner_exec);
  EXPECT_THROW(checkOutputPath((dir_ / "x.json").string()), Error);
  EXPECT_THROW(write(dir_ / "x.json", "x"), Error);
}

TEST_F(OutputFile, StandardOutputIsRecognised) {
  EXPECT_TRUE(isStandardOutput("-"));
  EXPECT_FALSE(isStandardOutput((dir_ / "nothing").string()));
}

}  // namespace
}  // namespace pnpba
