#pragma once
// The interactive app's entry point: a GLFW window (OpenGL 4.5 core), the
// renderer, Dear ImGui panels and the app state, run until the window
// closes or a script quits.
#include <optional>
#include <stdexcept>
#include <string>

namespace accelviz {

struct GuiOptions {
  std::optional<std::string> scene;   ///< file or builtin spec to open (else the last scene, else the demo)
  std::optional<std::string> script;  ///< --script FILE: run its commands, then quit
  bool use_settings = true;           ///< read and write settings and layout (off for scripts and tests)
  bool save_settings = true;          ///< off when the settings file is unusable and no copy of it was kept
  bool quiet = false;                 ///< no status lines on stderr (errors are always printed)
};

/// The window could not be opened (no display, no GL 4.5 core): the caller
/// may fall back to the headless demo.
class NoWindow : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// DISPLAY or WAYLAND_DISPLAY is set (a window is worth trying).
bool display_available();

/// Settings are off when ACCELVIZ_NO_SETTINGS is set to anything but "" or "0".
bool settings_disabled_by_environment();

/// Runs the app. Returns the exit code: 0, or 1 when a script failed.
/// Throws NoWindow when no window could be opened.
int run_gui(const GuiOptions& options);

}  // namespace accelviz
