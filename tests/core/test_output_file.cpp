// write_output_file (core/util/output_file.h): what every output of the
// tool goes through. Nothing the user had is lost: an existing file is kept
// unless overwriting is asked for, a failed write keeps the old file, and
// nothing already beside the target (a link, a FIFO, a leftover) is followed.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <map>
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

// `trace -o /dev/stdout -f > out.hits` replaced out.hits by rename: the
// program's later output went to the old, unlinked file, lost.
TEST_F(OutputFile, TheFileStandardOutputGoesToIsRefused) {
  write_file(path("out.hits"), "printed before");
  const int fd = ::open(path("out.hits").c_str(), O_WRONLY | O_APPEND);
  ASSERT_GE(fd, 0);
  std::fflush(stdout);
  const int saved = ::dup(1);
  ASSERT_GE(saved, 0);
  ASSERT_EQ(::dup2(fd, 1), 1);
  ::close(fd);
  const std::string by_name = output_path_problem(path("out.hits"));
  const std::string by_link = output_path_problem("/dev/stdout");
  const OutputWrite w = write_output_file(path("out.hits"), {"hits"}, true);
  ::dup2(saved, 1);
  ::close(saved);
  EXPECT_EQ(by_name, "is this program's standard output (name a file of its own)");
  EXPECT_EQ(by_link, by_name);
  EXPECT_EQ(w.problem, by_name);
  EXPECT_EQ(read_file(path("out.hits")), "printed before");
  // Once standard output goes elsewhere, the same name is an ordinary file to replace.
  EXPECT_TRUE(output_path_problem(path("out.hits")).empty());
  EXPECT_TRUE(others({"out.hits"}).empty());
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

// While alive, writes past `bytes` in one file fail with EFBIG (as a full
// disk fails them with ENOSPC) instead of raising SIGXFSZ.
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    EXPECT_EQ(::getrlimit(RLIMIT_FSIZE, &old_), 0);
    old_handler_ = std::signal(SIGXFSZ, SIG_IGN);
    struct rlimit small = old_;
    small.rlim_cur = bytes;
    EXPECT_EQ(::setrlimit(RLIMIT_FSIZE, &small), 0);
  }
  ~FileSizeLimit() {
    ::setrlimit(RLIMIT_FSIZE, &old_);
    std::signal(SIGXFSZ, old_handler_);
  }

 private:
  struct rlimit old_ {};
  void (*old_handler_)(int) = nullptr;
};

mode_t mode_of(const std::string& p) {
  struct stat st {};
  EXPECT_EQ(::stat(p.c_str(), &st), 0);
  return st.st_mode & 07777;
}

// The temporary was ".NAME.tmp-PID-N": a name the file system takes (here
// 250 bytes of 255) failed with "File name too long" after all the work.
TEST_F(OutputFile, ANameNearTheLimitIsWritten) {
  const std::string name = std::string(246, 'n') + ".png";
  for (const bool overwrite : {false, true}) {
    const OutputWrite w = write_output_file(path(name), {"x"}, overwrite);
    ASSERT_TRUE(w.ok()) << w.problem;
  }
  EXPECT_EQ(read_file(path(name)), "x");
  EXPECT_TRUE(others({name}).empty());
}

// A name the file system cannot take is said before any work (the CLI's
// check_output_path asks output_path_problem), in one line.
TEST_F(OutputFile, ANameTooLongIsRefusedBeforeTheWork) {
  const std::string name = std::string(296, 'n') + ".png";
  const std::string problem = output_path_problem(path(name));
  EXPECT_EQ(problem, "a name in it is 300 bytes long; the file system takes at most 255");
  EXPECT_EQ(output_path_problem(path("missing/" + name)), problem);  // a folder yet to be made: its parent's limit
  EXPECT_EQ(write_output_file(path(name), {"x"}, true).problem, problem);
  EXPECT_TRUE(name_length_problem(path(std::string(255, 'n'))).empty());
}

// rename gave the name a new file of mode 0666 & ~umask: a private 0600 file
// became world-readable when replaced.
TEST_F(OutputFile, ReplacingAFileKeepsItsPermissionBits) {
  const mode_t old_umask = ::umask(022);
  write_file(path("private.json"), "secret");
  ASSERT_EQ(::chmod(path("private.json").c_str(), 0600), 0);
  write_file(path("readonly.json"), "old");
  ASSERT_EQ(::chmod(path("readonly.json").c_str(), 0444), 0);
  const OutputWrite a = write_output_file(path("private.json"), {"new secret"}, true);
  const OutputWrite b = write_output_file(path("readonly.json"), {"new"}, true);
  const OutputWrite fresh = write_output_file(path("fresh.json"), {"x"}, true);
  ::umask(old_umask);
  ASSERT_TRUE(a.ok() && b.ok() && fresh.ok()) << a.problem << b.problem << fresh.problem;
  EXPECT_EQ(mode_of(path("private.json")), 0600u);
  EXPECT_EQ(read_file(path("private.json")), "new secret");
  EXPECT_EQ(mode_of(path("readonly.json")), 0444u);
  EXPECT_EQ(mode_of(path("fresh.json")), 0644u);  // a new file: the umask's
}

TEST_F(OutputFile, ReplacingAFileAsRootKeepsItsOwner) {
  if (::geteuid() != 0) GTEST_SKIP() << "only root may give a file to another user";
  write_file(path("theirs.png"), "old");
  ASSERT_EQ(::chown(path("theirs.png").c_str(), 4321, 4322), 0);
  ASSERT_TRUE(write_output_file(path("theirs.png"), {"new"}, true).ok());
  struct stat st {};
  ASSERT_EQ(::stat(path("theirs.png").c_str(), &st), 0);
  EXPECT_EQ(st.st_uid, 4321u);
  EXPECT_EQ(st.st_gid, 4322u);
}

// Inherent to an atomic replacement (documented): the name gets a new file,
// a second hard link to the old one keeps the old bytes.
TEST_F(OutputFile, AHardLinkToTheReplacedFileKeepsTheOldContent) {
  write_file(path("a.csv"), "old");
  fs::create_hard_link(path("a.csv"), path("b.csv"));
  ASSERT_TRUE(write_output_file(path("a.csv"), {"new"}, true).ok());
  EXPECT_EQ(read_file(path("a.csv")), "new");
  EXPECT_EQ(read_file(path("b.csv")), "old");
}

// ---- sets of files: all or nothing (render -s a,b; render --compare) ----

// The second file's write fails (a full disk): the first, already written,
// must not have taken its name.
TEST_F(OutputFile, ASetWhoseSecondWriteFailsChangesNothing) {
  write_file(path("T-bvh.png"), "old bvh");
  write_file(path("T-kdtree.png"), "old kdtree");
  OutputWrite w;
  {
    const FileSizeLimit limit(1024);
    w = write_output_files({{path("T-bvh.png"), "new bvh"}, {path("T-kdtree.png"), std::string(4096, 'k')}}, true);
  }
  EXPECT_EQ(w.problem, "write failed: File too large");
  EXPECT_EQ(w.path, path("T-kdtree.png"));
  EXPECT_EQ(read_file(path("T-bvh.png")), "old bvh");
  EXPECT_EQ(read_file(path("T-kdtree.png")), "old kdtree");
  EXPECT_TRUE(others({"T-bvh.png", "T-kdtree.png"}).empty());
}

// A name taken while the set was written (without overwrite): the names the
// set already gave are taken back.
TEST_F(OutputFile, ASetUndoesItsNamesWhenOneIsTakenMeanwhile) {
  OutputFileSet set(false);
  ASSERT_TRUE(set.add(path("a.png"), {"a"}).ok());
  ASSERT_TRUE(set.add(path("b.png"), {"b"}).ok());
  write_file(path("b.png"), "someone else's");
  const OutputWrite w = set.commit();
  EXPECT_TRUE(w.exists);
  EXPECT_EQ(w.path, path("b.png"));
  EXPECT_FALSE(fs::exists(path("a.png")));
  EXPECT_EQ(read_file(path("b.png")), "someone else's");
  EXPECT_TRUE(others({"b.png"}).empty());
}

// With overwrite, a rename that fails after others succeeded (here the last
// target became a folder) puts the replaced files back.
TEST_F(OutputFile, ASetPutsReplacedFilesBackWhenARenameFails) {
  write_file(path("a.png"), "old a");
  OutputFileSet set(true);
  ASSERT_TRUE(set.add(path("a.png"), {"new a"}).ok());
  ASSERT_TRUE(set.add(path("new.png"), {"new"}).ok());
  ASSERT_TRUE(set.add(path("c.png"), {"new c"}).ok());
  fs::create_directories(path("c.png/inside"));
  const OutputWrite w = set.commit();
  EXPECT_FALSE(w.ok());
  EXPECT_EQ(w.path, path("c.png"));
  EXPECT_EQ(read_file(path("a.png")), "old a");
  EXPECT_FALSE(fs::exists(path("new.png")));
  EXPECT_TRUE(others({"a.png", "c.png"}).empty());
}

TEST_F(OutputFile, ASetDroppedUncommittedLeavesNoTemporary) {
  {
    OutputFileSet set(true);
    ASSERT_TRUE(set.add(path("a.png"), {"a"}).ok());
  }
  EXPECT_TRUE(others({}).empty());
}

// ---- OutputFolder: sweep's and refit's DIR ----

class OutputFolderTest : public OutputFile {
 protected:
  const std::vector<std::string> known_ = {"sweep.csv", "sweep.json", "sweep-pareto.png", "sweep-sah_cost-vs-leaf.png",
                                           "sweep-sah_cost-vs-buckets.png"};
  /// name -> content of every file under `d`.
  static std::map<std::string, std::string> contents(const fs::path& d) {
    std::map<std::string, std::string> m;
    for (const auto& e : fs::directory_iterator(d)) m[e.path().filename().string()] = read_file(e.path().string());
    return m;
  }
};

// A write that fails midway (a full disk) with --force: the old results were
// deleted before the new ones were written, and a partial set was left.
TEST_F(OutputFolderTest, AFailedRunWithForceLeavesTheFolderAsItWas) {
  const std::string out = path("out");
  fs::create_directories(out);
  write_file(out + "/sweep.csv", "old csv");
  write_file(out + "/sweep.json", "old json");
  write_file(out + "/sweep-sah_cost-vs-buckets.png", "old chart");
  const auto before = contents(out);
  {
    OutputFolder folder(out, known_, true);
    ASSERT_TRUE(folder.open().ok());
    ASSERT_TRUE(folder.add("sweep.csv", {"new csv"}).ok());
    const FileSizeLimit limit(1024);
    const OutputWrite w = folder.add("sweep.json", {std::string(4096, 'j')});
    EXPECT_EQ(w.problem, "write failed: File too large");
  }  // dropped: the run failed
  EXPECT_EQ(contents(out), before);
}

TEST_F(OutputFolderTest, AFolderTheFailedRunMadeIsRemovedAgain) {
  const std::string out = path("new/out");
  {
    OutputFolder folder(out, known_, false);
    ASSERT_TRUE(folder.open().ok());
    ASSERT_TRUE(fs::is_directory(out));
    const FileSizeLimit limit(1024);
    EXPECT_FALSE(folder.add("sweep.csv", {std::string(4096, 'c')}).ok());
  }
  EXPECT_TRUE(others({}).empty());  // neither new/ nor new/out
}

// --force removed any sweep-*.png, a user's own notes too; only the names the
// command writes are replaced or removed (an earlier run's chart of another
// parameter, stale, is).
TEST_F(OutputFolderTest, OnlyTheSchemesNamesAreReplacedOrRemoved) {
  const std::string out = path("out");
  fs::create_directories(out);
  write_file(out + "/sweep-mynotes.png", "mine");
  write_file(out + "/sweep.csv", "old csv");
  write_file(out + "/sweep-sah_cost-vs-buckets.png", "stale chart");
  OutputFolder folder(out, known_, true);
  ASSERT_TRUE(folder.open().ok());
  ASSERT_TRUE(folder.add("sweep.csv", {"new csv"}).ok());
  ASSERT_TRUE(folder.add("sweep-sah_cost-vs-leaf.png", {"new chart"}).ok());
  EXPECT_EQ(contents(out)["sweep.csv"], "old csv");  // nothing takes its name before commit
  ASSERT_TRUE(folder.commit().ok());
  EXPECT_TRUE(folder.stale_left().empty());
  const std::map<std::string, std::string> want = {
      {"sweep-mynotes.png", "mine"}, {"sweep.csv", "new csv"}, {"sweep-sah_cost-vs-leaf.png", "new chart"}};
  EXPECT_EQ(contents(out), want);
}

TEST_F(OutputFolderTest, WithoutOverwriteOnlyTheSchemesNamesRefuse) {
  const std::string out = path("out");
  fs::create_directories(out);
  write_file(out + "/sweep-mynotes.png", "mine");
  bool holds = true;
  EXPECT_EQ(OutputFolder::problem(out, known_, false, &holds), "");
  EXPECT_FALSE(holds);
  write_file(out + "/sweep.json", "old");
  EXPECT_EQ(OutputFolder::problem(out, known_, false, &holds), "holds sweep.json");
  EXPECT_TRUE(holds);
  EXPECT_EQ(OutputFolder::problem(out, known_, true, &holds), "");
  ASSERT_EQ(::mkfifo((out + "/sweep.csv").c_str(), 0644), 0);
  EXPECT_EQ(OutputFolder::problem(out, known_, true), "sweep.csv: is not a regular file (a FIFO, device or socket)");
  write_file(path("file"), "x");
  EXPECT_EQ(OutputFolder::problem(path("file"), known_, true), "exists and is not a directory");
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
