// write_output_file (core/util/output_file.h): what every output of the
// tool goes through. Nothing the user had is lost: an existing file is kept
// unless overwriting is asked for, a failed write keeps the old file, and
// nothing already beside the target (a link, a FIFO, a leftover) is followed.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <filesystem>
#include <string>
#include <vector>

#include "core/util/file_checks.h"
#include "core/util/output_file.h"
#include "tests/support/temp_dir.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_output_file {

using namespace accelviz;
namespace fs = std::filesystem;
using test_support::read_file;
using test_support::write_file;

class OutputFile : public test_support::TempDirTest {
 protected:
  /// Names in the folder other than `keep`: a temporary left behind shows here.
  std::vector<std::string> others(std::initializer_list<std::string> keep) const {
    std::vector<std::string> out;
    for (const auto& e : fs::directory_iterator(dir_)) {
      const std::string n = e.path().filename().string();
      if (std::find(keep.begin(), keep.end(), n) == keep.end()) out.push_back(n);
    }
    return out;
  }
};

TEST_F(OutputFile, WritesThePartsAndLeavesNoTemporary) {
  const OutputWrite w = write_output_file(path("a.bin"), {"head", "", "er+body"}, false);
  ASSERT_TRUE(w.ok()) << w.problem;
  EXPECT_EQ(read_file(path("a.bin")), "header+body");
  EXPECT_TRUE(others({"a.bin"}).empty());
}

TEST_F(OutputFile, AnExistingFileIsKeptUnlessOverwriteIsAsked) {
  write_file(path("a.png"), "mine");
  const OutputWrite refused = write_output_file(path("a.png"), {"new"}, false);
  EXPECT_TRUE(refused.exists);
  EXPECT_EQ(refused.problem, "exists");
  EXPECT_EQ(read_file(path("a.png")), "mine");
  EXPECT_TRUE(others({"a.png"}).empty());
  const OutputWrite replaced = write_output_file(path("a.png"), {"new"}, true);
  ASSERT_TRUE(replaced.ok()) << replaced.problem;
  EXPECT_EQ(read_file(path("a.png")), "new");
  EXPECT_TRUE(others({"a.png"}).empty());
}

TEST_F(OutputFile, ADanglingLinkCountsAsExisting) {
  fs::create_symlink(path("nowhere"), path("a.png"));
  EXPECT_TRUE(write_output_file(path("a.png"), {"new"}, false).exists);
  EXPECT_FALSE(fs::exists(path("nowhere")));
}

TEST_F(OutputFile, OverwritingThroughALinkReplacesTheFileItNames) {
  write_file(path("real.json"), "old");
  fs::create_symlink("real.json", path("link.json"));
  const OutputWrite w = write_output_file(path("link.json"), {"new"}, true);
  ASSERT_TRUE(w.ok()) << w.problem;
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(path("link.json"))));
  EXPECT_EQ(read_file(path("real.json")), "new");
}

// With overwrite, a dangling link is followed too: the file it names is made
// and the link stays (the link itself was replaced by a regular file).
TEST_F(OutputFile, OverwritingThroughADanglingLinkMakesTheFileItNames) {
  fs::create_directories(path("sub"));
  fs::create_symlink("sub/made.json", path("dangling.json"));
  const OutputWrite w = write_output_file(path("dangling.json"), {"new"}, true);
  ASSERT_TRUE(w.ok()) << w.problem;
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(path("dangling.json"))));
  EXPECT_EQ(read_file(path("sub/made.json")), "new");
}

// What lies beside the target under the names a writer might have used for
// its temporary (export used OUT.part: a link there made it overwrite the
// file the link named, a FIFO there made it hang) is never opened.
TEST_F(OutputFile, LinksAndFifosBesideTheTargetAreNotFollowed) {
  write_file(path("victim.txt"), "precious");
  fs::create_symlink("victim.txt", path("a.glb.part"));
  ASSERT_EQ(::mkfifo(path("b.glb.part").c_str(), 0644), 0);
  for (const char* name : {"a.glb", "b.glb"}) {
    const OutputWrite w = write_output_file(path(name), {"glb bytes"}, false);
    ASSERT_TRUE(w.ok()) << w.problem;
    EXPECT_EQ(read_file(path(name)), "glb bytes");
  }
  EXPECT_EQ(read_file(path("victim.txt")), "precious");
  EXPECT_TRUE(others({"victim.txt", "a.glb.part", "b.glb.part", "a.glb", "b.glb"}).empty());
}

TEST_F(OutputFile, AFifoOrAFolderAsTheTargetIsRefused) {
  ASSERT_EQ(::mkfifo(path("pipe.png").c_str(), 0644), 0);
  fs::create_directories(path("folder.png"));
  for (const bool overwrite : {false, true}) {
    EXPECT_EQ(write_output_file(path("pipe.png"), {"x"}, overwrite).problem,
              "is not a regular file (a FIFO, device or socket)");
    EXPECT_EQ(write_output_file(path("folder.png"), {"x"}, overwrite).problem, "is a directory");
  }
  EXPECT_TRUE(others({"pipe.png", "folder.png"}).empty());
}

TEST_F(OutputFile, AMissingFolderIsNamed) {
  const OutputWrite w = write_output_file(path("no/such/a.png"), {"x"}, false);
  EXPECT_FALSE(w.ok());
  EXPECT_EQ(w.problem, "cannot create: No such file or directory");
}

// A write that fails part-way (here a file-size limit, as a full disk would)
// keeps the file that was there and leaves no temporary.
TEST_F(OutputFile, AFailedWriteKeepsTheOldFile) {
  write_file(path("big.png"), "ORIGINAL");
  struct rlimit old {};
  ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &old), 0);
  void (*old_handler)(int) = std::signal(SIGXFSZ, SIG_IGN);  // EFBIG instead of the signal
  struct rlimit small = old;
  small.rlim_cur = 1024;
  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &small), 0);
  const std::string big(4096, 'x');
  const OutputWrite w = write_output_file(path("big.png"), {big}, true);
  ::setrlimit(RLIMIT_FSIZE, &old);
  std::signal(SIGXFSZ, old_handler);
  EXPECT_EQ(w.problem, "write failed: File too large");
  EXPECT_EQ(read_file(path("big.png")), "ORIGINAL");
  EXPECT_TRUE(others({"big.png"}).empty());
}

// read_text_file: what the app's own small files (settings, layout, shaders,
// scripts) are read with. A FIFO would block the reader, a folder read as
// empty, a huge file would be read whole.
TEST_F(OutputFile, ReadTextFileTakesOnlySmallRegularFiles) {
  write_file(path("ok.ini"), "[Window][A]\n");
  ASSERT_EQ(::mkfifo(path("fifo.ini").c_str(), 0644), 0);
  fs::create_directories(path("dir.ini"));
  write_file(path("big.ini"), std::string(2048, 'x'));
  std::string text;
  EXPECT_EQ(read_text_file(path("ok.ini"), 1024, text), "");
  EXPECT_EQ(text, "[Window][A]\n");
  EXPECT_EQ(read_text_file(path("fifo.ini"), 1024, text), "is not a regular file");
  EXPECT_EQ(read_text_file(path("dir.ini"), 1024, text), "is a directory, not a file");
  EXPECT_EQ(read_text_file(path("big.ini"), 1024, text), "is larger than 1024 bytes");
  EXPECT_EQ(read_text_file(path("none.ini"), 1024, text), "no such file");
}

}  // namespace unity_test_output_file
