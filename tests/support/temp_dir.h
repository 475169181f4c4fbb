#pragma once
// Temporary folders for the tests (core, app, gl, gui): a fresh, empty,
// uniquely named folder per use, removed afterwards, and whole-file reads and
// writes. One definition instead of one per test file. Named namespace: the
// test sources are compiled as unity builds (tests/CMakeLists.txt), where
// many files have their own `read`, `write_file` or `TempDir` helpers.
#include <gtest/gtest.h>

#include <cctype>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>

namespace accelviz::test_support {

/// A fresh empty folder <temp dir>/accelviz-<tag>-XXXXXX (mkdtemp), removed
/// with everything in it by the destructor.
class TempDir {
 public:
  explicit TempDir(std::string_view tag = "test") {
    std::string pattern =
        (std::filesystem::temp_directory_path() / ("accelviz-" + std::string(tag) + "-XXXXXX")).string();
    if (!::mkdtemp(pattern.data())) throw std::runtime_error(pattern + ": mkdtemp failed: " + std::strerror(errno));
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  /// The path of `name` in the folder.
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

/// A fixture whose every test gets its own fresh folder dir_, named after
/// the test suite unless a tag is given.
class TempDirTest : public ::testing::Test {
 protected:
  TempDirTest() : TempDirTest(suite_tag()) {}
  explicit TempDirTest(std::string_view tag) : tmp_(tag), dir_(tmp_.path()) {}

  /// The path of `name` in dir_.
  std::string path(const std::string& name) const { return (dir_ / name).string(); }

 private:
  static std::string suite_tag() {
    const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string tag = info ? info->test_suite_name() : "test";
    for (char& c : tag)
      if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';  // "Prefix/Suite" of parameterised tests
    return tag;
  }

  TempDir tmp_;  // before dir_: initialised first

 protected:
  std::filesystem::path dir_;
};

/// The whole file (binary); "" when it cannot be read.
inline std::string read_file(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Writes `bytes` as the whole file (binary, replacing what was there).
inline void write_file(const std::filesystem::path& p, std::string_view bytes) {
  std::ofstream(p, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

}  // namespace accelviz::test_support
