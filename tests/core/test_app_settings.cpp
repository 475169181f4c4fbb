// Settings on disk: round trip, atomic replacement, the XDG location, and
// unusable files reported in one line and replaced by defaults.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdlib>
#include <filesystem>

#include "tests/support/temp_dir.h"
#include "ui/app/settings.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_app_settings {

using namespace accelviz;
namespace fs = std::filesystem;

namespace {

using test_support::read_file;
using test_support::TempDir;
using test_support::write_file;

// Restores an environment variable on scope exit.
class EnvGuard {
 public:
  explicit EnvGuard(const char* name) : name_(name) {
    if (const char* v = std::getenv(name)) old_ = v;
  }
  ~EnvGuard() {
    if (old_)
      setenv(name_, old_->c_str(), 1);
    else
      unsetenv(name_);
  }

 private:
  const char* name_;
  std::optional<std::string> old_;
};

}  // namespace

TEST(AppSettings, RoundTrip) {
  TempDir dir("settings");
  AppSettings s;
  s.last_scene = "/data/bunny.glb";
  s.recent = {"/data/bunny.glb", "builtin:teapot?size=5000"};
  s.screenshot_dir = "/tmp/shots";
  s.window_width = 1600;
  s.window_height = 900;
  ASSERT_EQ(apply_option(s.config, "structure", "octree"), "");
  ASSERT_EQ(apply_option(s.config, "octree-depth", "7"), "");
  ASSERT_EQ(apply_option(s.config, "buckets", "64"), "");
  ASSERT_EQ(apply_option(s.config, "heatmap", "blend"), "");
  ASSERT_EQ(apply_option(s.config, "scale", "1,30"), "");
  ASSERT_EQ(apply_option(s.config, "wireframe", "on"), "");
  const fs::path file = settings_file(dir.path() / "accelviz");
  ASSERT_EQ(save_settings(file, s), "");

  const LoadedSettings loaded = load_settings(file);
  EXPECT_EQ(loaded.error, "");
  EXPECT_EQ(loaded.settings.last_scene, s.last_scene);
  EXPECT_EQ(loaded.settings.recent, s.recent);
  EXPECT_EQ(loaded.settings.screenshot_dir, s.screenshot_dir);
  EXPECT_EQ(loaded.settings.window_width, 1600);
  EXPECT_EQ(loaded.settings.window_height, 900);
  EXPECT_EQ(option_values(loaded.settings.config), option_values(s.config));
}

TEST(AppSettings, MissingFileGivesDefaultsSilently) {
  TempDir dir("settings");
  const LoadedSettings loaded = load_settings(dir.path() / "none" / "settings.json");
  EXPECT_EQ(loaded.error, "");
  EXPECT_EQ(option_values(loaded.settings.config), option_values(AppConfig{}));
  EXPECT_TRUE(loaded.settings.recent.empty());
}

TEST(AppSettings, CorruptedFileIsReportedAndReplacedByDefaults) {
  TempDir dir("settings");
  const fs::path file = dir.path() / "settings.json";
  struct Case {
    const char* text;
    const char* problem;
  };
  for (const Case& c : {
           Case{"{\"version\": 1, \"options\": {\"buckets\": ", "parse error"},
           Case{"", "parse error"},
           Case{"[1, 2]", "not a JSON object"},
           Case{"{\"version\": 7}", "unsupported version 7"},
           Case{"{\"recent\": \"x\"}", "recent: expected an array of strings"},
           Case{"{\"last_scene\": 3}", "last_scene: expected a string"},
           Case{"{\"window\": {\"width\": 5}}", "window.width: expected an integer in 100..8192"},
           Case{"{\"window\": {\"width\": 16384}}", "window.width: expected an integer in 100..8192"},
           Case{"{\"window\": \"big\"}", "window: expected an object with width and height"},
           Case{"{\"window\": {\"depth\": 3}}", "window: unknown key 'depth'"},
           Case{"{\"bogus\": 1}", "unknown key 'bogus'"},
           Case{"{\"version\": 4294967297}", "unsupported version 4294967297"},
           Case{"{\"options\": {\"buckets\": \"1\"}}", "options.buckets: expected an integer in 2..256, got '1'"},
           Case{"{\"options\": {\"buckets\": 16}}", "options.buckets: expected a string"},
           Case{"{\"options\": {\"wobble\": \"on\"}}", "options: unknown option 'wobble'"},
       }) {
    write_file(file, c.text);
    const LoadedSettings loaded = load_settings(file);
    EXPECT_EQ(loaded.error.rfind(file.string() + ": ", 0), 0u) << loaded.error;
    EXPECT_NE(loaded.error.find(c.problem), std::string::npos) << c.text << " -> " << loaded.error;
    // The defaults replace the file at the next save: a copy is kept first, never over an earlier one.
    const std::string kept = "(using defaults; the file is kept as " + file.string() + ".bad";
    ASSERT_NE(loaded.error.find(kept), std::string::npos) << loaded.error;
    const std::size_t from = loaded.error.find(kept) + std::string("(using defaults; the file is kept as ").size();
    const std::string copy = loaded.error.substr(from, loaded.error.size() - 1 - from);
    EXPECT_EQ(read_file(copy), c.text) << copy;
    EXPECT_EQ(loaded.error.find('\n'), std::string::npos) << "one line";
    EXPECT_EQ(option_values(loaded.settings.config), option_values(AppConfig{})) << c.text;
    EXPECT_EQ(loaded.settings.last_scene, "");
  }
  // Saving afterwards replaces the bad file with a readable one.
  ASSERT_EQ(save_settings(file, load_settings(file).settings), "");
  EXPECT_EQ(load_settings(file).error, "");
}

// A FIFO blocked the app's start; a folder read as a parse error; a huge
// file was read whole. Each is one line and the defaults.
TEST(AppSettings, AFifoFolderOrHugeFileIsReportedNotRead) {
  TempDir dir("settings");
  ASSERT_EQ(::mkfifo((dir.path() / "fifo.json").c_str(), 0644), 0);
  fs::create_directories(dir.path() / "dir.json");
  write_file(dir.path() / "huge.json", "{\"last_scene\": \"" + std::string(kMaxSettingsBytes, 'x') + "\"}");
  for (const auto& [name, problem] :
       {std::pair{"fifo.json", "is not a regular file"}, std::pair{"dir.json", "is a directory, not a file"},
        std::pair{"huge.json", "is larger than 1048576 bytes"}}) {
    const LoadedSettings loaded = load_settings(dir.path() / name);
    EXPECT_EQ(loaded.error, (dir.path() / name).string() + ": " + problem +
                                " (using defaults; the file is left as it is: settings are not saved this session)");
    EXPECT_TRUE(loaded.leave_file) << "not read, so not copied: a save would replace it";
    EXPECT_EQ(loaded.settings.last_scene, "");
  }
}

// A malformed file whose copy cannot be made (here a folder has the name .bad, and another .bad-2;
// a full disk fails them all) is copied to the next free name; where none takes it, the file is left
// as it is and not saved over (the defaults replaced it: the recent list and folders were lost).
TEST(AppSettings, AMalformedFileIsNeverSavedOverWithoutACopy) {
  TempDir dir("settings");
  const fs::path file = dir.path() / "settings.json";
  write_file(file, "{\"options\": {\"buckets\": \"1\"}}");
  fs::create_directories(dir.path() / "settings.json.bad");
  fs::create_directories(dir.path() / "settings.json.bad-2");
  LoadedSettings loaded = load_settings(file);
  EXPECT_FALSE(loaded.leave_file) << loaded.error;
  EXPECT_NE(loaded.error.find("the file is kept as " + file.string() + ".bad-3)"), std::string::npos) << loaded.error;
  EXPECT_EQ(read_file(dir.path() / "settings.json.bad-3"), "{\"options\": {\"buckets\": \"1\"}}");
  // Every name a folder: no copy, the file left alone.
  for (int k = 3; k <= 1000; ++k) {
    fs::remove(dir.path() / ("settings.json.bad-" + std::to_string(k)));
    fs::create_directories(dir.path() / ("settings.json.bad-" + std::to_string(k)));
  }
  loaded = load_settings(file);
  EXPECT_TRUE(loaded.leave_file);
  EXPECT_NE(loaded.error.find("(using defaults; no copy kept: " + file.string() +
                              ".bad: is a directory, so the file is left as it is: settings are not "
                              "saved this session)"),
            std::string::npos)
      << loaded.error;
}

TEST(AppSettings, AtomicWriteReplacesWholeFilesAndLeavesNoTemporary) {
  TempDir dir("settings");
  const fs::path file = dir.path() / "sub" / "dir" / "f.txt";
  ASSERT_EQ(write_file_atomic(file, "first version, rather long\n"), "");
  EXPECT_EQ(read_file(file), "first version, rather long\n");
  ASSERT_EQ(write_file_atomic(file, "second\n"), "");
  EXPECT_EQ(read_file(file), "second\n") << "replaced, not overwritten in place (no tail of the old text)";
  ASSERT_EQ(write_file_atomic(file, ""), "");
  EXPECT_EQ(read_file(file), "");
  std::size_t entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(file.parent_path())) ++entries;
  EXPECT_EQ(entries, 1u) << "no temporary file left next to it";
}

TEST(AppSettings, AtomicWriteFailureIsOneLineAndKeepsTheOldFile) {
  TempDir dir("settings");
  // A directory where the file should be: rename() cannot replace it.
  const fs::path target = dir.path() / "taken";
  fs::create_directories(target / "inside");
  const std::string e = write_file_atomic(target, "text");
  EXPECT_EQ(e.rfind(target.string() + ": ", 0), 0u) << e;
  EXPECT_TRUE(fs::is_directory(target / "inside"));
  std::size_t entries = 0;
  for ([[maybe_unused]] const auto& x : fs::directory_iterator(dir.path())) ++entries;
  EXPECT_EQ(entries, 1u) << "the temporary file was removed";
  // A parent that is a file cannot become a folder.
  write_file(dir.path() / "plain", "x");
  EXPECT_NE(write_file_atomic(dir.path() / "plain" / "f.txt", "text"), "");
}

TEST(AppSettings, ConfigDirFollowsXdg) {
  EnvGuard xdg("XDG_CONFIG_HOME"), home("HOME");
  setenv("XDG_CONFIG_HOME", "/cfg/here", 1);
  EXPECT_EQ(config_dir(), fs::path("/cfg/here/accelviz"));
  setenv("XDG_CONFIG_HOME", "relative/path", 1);  // invalid per the spec: ignored
  setenv("HOME", "/home/someone", 1);
  EXPECT_EQ(config_dir(), fs::path("/home/someone/.config/accelviz"));
  unsetenv("XDG_CONFIG_HOME");
  EXPECT_EQ(config_dir(), fs::path("/home/someone/.config/accelviz"));
  EXPECT_EQ(settings_file(config_dir()).filename(), "settings.json");
  EXPECT_EQ(imgui_ini_file(config_dir()).filename(), "imgui.ini");
}

TEST(AppSettings, RecentFilesMostRecentFirstWithoutDuplicates) {
  AppSettings s;
  for (int i = 0; i < 15; ++i) add_recent(s, "scene" + std::to_string(i));
  ASSERT_EQ(s.recent.size(), AppSettings::kMaxRecent);
  EXPECT_EQ(s.recent.front(), "scene14");
  add_recent(s, "scene10");
  EXPECT_EQ(s.recent.front(), "scene10");
  EXPECT_EQ(std::count(s.recent.begin(), s.recent.end(), "scene10"), 1);
  add_recent(s, "");
  EXPECT_EQ(s.recent.front(), "scene10");
}
}  // namespace unity_test_app_settings
