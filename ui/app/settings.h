#pragma once
// App settings on disk: the last scene, the structure and its options, the
// view toggles, recent files, the screenshot folder and the window size, as
// one JSON file under $XDG_CONFIG_HOME/accelviz/ (default ~/.config/accelviz/),
// next to ImGui's window layout (imgui.ini). Files are replaced atomically
// (temporary file + rename), so a crash never leaves half a file; a file that
// cannot be read is reported in one line and replaced by defaults.
//
// Precedence: defaults < settings file < command line < interactive changes.
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "ui/app/app_config.h"

namespace accelviz {

struct AppSettings {
  static constexpr std::size_t kMaxRecent = 10;

  AppConfig config;
  std::string last_scene;           ///< opened when the app starts without a file ("" = the demo scene)
  std::vector<std::string> recent;  ///< most recent first, no duplicates, at most kMaxRecent
  std::string screenshot_dir;       ///< "" = default_screenshot_dir()
  int window_width = 1280;          ///< screen coordinates
  int window_height = 800;
};

/// Puts `spec` first in the recent list (removing an older entry, trimming to kMaxRecent).
void add_recent(AppSettings& s, const std::string& spec);

/// $XDG_CONFIG_HOME/accelviz when XDG_CONFIG_HOME is set and absolute, else
/// $HOME/.config/accelviz (XDG Base Directory specification).
std::filesystem::path config_dir();
inline std::filesystem::path settings_file(const std::filesystem::path& dir) {
  return dir / "settings.json";
}
inline std::filesystem::path imgui_ini_file(const std::filesystem::path& dir) {
  return dir / "imgui.ini";
}

/// Settings as written to disk: {"version": 1, "last_scene", "recent",
/// "screenshot_dir", "window": {"width", "height"}, "options": {KEY: VALUE},
/// "effects": {"shadow-rays", "per-frame-updates", "two-level": bool}} with
/// every key of option_table() (values as option_value writes them) and the
/// effect forces (AppConfig::effects).
nlohmann::json settings_to_json(const AppSettings& s);
/// The reverse; throws std::runtime_error with one line naming the first
/// problem (wrong type, unknown version, an option apply_option refuses).
/// Keys absent from the file keep their defaults.
AppSettings settings_from_json(const nlohmann::json& j);

struct LoadedSettings {
  AppSettings settings;  ///< defaults when the file is missing or unusable
  std::string error;     ///< one line when the file exists but was unusable ("" otherwise)
  /// The file is unusable and no copy of it could be kept (a full disk, a folder where the copy
  /// goes, a file over kMaxSettingsBytes): saving would lose it, so the session must not write it.
  bool leave_file = false;
};
/// Largest settings file read (and imgui.ini): both are a few KB.
inline constexpr std::uintmax_t kMaxSettingsBytes = std::uintmax_t{1} << 20;

/// Reads `file`. A missing file gives defaults without an error; a
/// malformed one, or one that is not a regular file of at most
/// kMaxSettingsBytes, gives defaults and "<file>: <problem> (using defaults)". A malformed file is
/// first copied to FILE.bad (or .bad-2, ...: the first free name that takes the copy); where no copy
/// is kept, `leave_file` is set and the message says the file is left as it is.
LoadedSettings load_settings(const std::filesystem::path& file);

/// Writes `content` to `file` atomically: core's write_output_file (a fresh
/// temporary file in the same folder, flushed, then renamed over `file`),
/// the folder created if missing. Returns
/// "" on success, else one line "<file>: <problem>"; never leaves the
/// temporary file behind.
std::string write_file_atomic(const std::filesystem::path& file, std::string_view content);

/// Writes a file the user asked for by name (a script's dump-* commands)
/// as a new file: an existing one is never replaced ("<file>: exists (not
/// overwritten)"), and, as for screenshots, a missing folder is an error.
/// Through core's write_output_file. Returns "" or one line.
std::string write_new_file(const std::filesystem::path& file, std::string_view content);

/// settings_to_json, pretty-printed, through write_file_atomic.
std::string save_settings(const std::filesystem::path& file, const AppSettings& s);

}  // namespace accelviz
