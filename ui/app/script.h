#pragma once
// `accelviz --script FILE`: a session driven by a small command list, one
// command per line, run by the real window's main loop between frames (see
// docs/gui.md for the language). Parsing and sequencing live here, GL-free;
// the GUI implements ScriptHost to carry commands out.
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "core/util/one_line.h"

namespace accelviz {

struct ScriptCommand {
  enum class Kind {
    open,
    structure,
    set,
    camera,
    size,
    wait,
    click,
    step,
    screenshot,
    dump_ray,
    dump_stats,
    quit,
    scenario,       ///< arg: scenario id, value: slider value (insight: Scenarios window)
    dump_scenario,  ///< arg: path; waits for the scenario's run, writes its figures
    dump_insight,   ///< arg: path; measures the view (predicted vs measured, modes, hot nodes, explainer), writes JSON
    force_effect,   ///< arg: effect name, value: "on" | "off" (Scene panel's force checkbox)
    play,           ///< x: frames; plays the Dynamics timeline until that many more frames were stepped
    dump_dynamics,  ///< arg: path; the effects and the Dynamics panel's per-frame figures as JSON
    select_region,  ///< x, y, x2, y2: a rectangle of the 3D view (pixels); selects the insight record's pixels under it
    pin_a,          ///< pins the current structure and query options as A (A/B compare)
    dump_ab,        ///< arg: path; compares A with the current choice (B) on this view, writes the totals as JSON
    frames,         ///< x: frames; lets that many frames draw before the next command (no waiting on work)
    flatten,        ///< arg: instance ids ("0,2,5-9", "all"); predicts the flatten what-if on this view, waits
    flatten_commit,   ///< commits the last prediction (its instances merged) and waits for the merged scene's build
    dump_flatten,     ///< arg: path; the last prediction's figures as JSON
    reload_shaders,   ///< arg: "" or a folder (then the shader override folder); rebuilds the shader programs
    window,           ///< value: "open" | "close", arg: a panel's title (kPanelTitles); expands or collapses it
    sweep,            ///< arg: parameters ("buckets=2,8 leaf=1,4"); runs the Cost of accuracy sweep on this view
    dump_sweep,       ///< arg: path; waits for the sweep, writes its settings' figures as JSON
    robustness,       ///< x: rays (0: the window's count); runs the Robustness window's lab on the shown scene
    dump_robustness,  ///< arg: path; waits for the lab, writes its variants' figures as JSON
    cancel,           ///< arg: "build" | "sweep" | "robustness"; that window's Cancel button
  };
  Kind kind = Kind::wait;
  int line = 0;        ///< 1-based line in the script file
  std::string text;    ///< the line as written (trimmed), for messages
  std::string arg;     ///< open: scene; structure: name; set: key; camera: spec; step: N|next|prev|first|last;
                       ///< screenshot/dump-*: path
  std::string value;   ///< set: value
  int x = 0, y = 0;    ///< size: width, height; click: pixel; select-region: first corner; frames: count
  int x2 = 0, y2 = 0;  ///< select-region: second corner
};

/// The command's name as written in scripts ("dump-ray").
std::string_view command_name(ScriptCommand::Kind kind);
/// Every command's name, in the order of the script language's table.
std::vector<std::string_view> script_command_names();

/// A parse or run error; what() is "FILE:LINE: message".
class ScriptError : public std::runtime_error {
 public:
  /// The message is made one line (first_line: control bytes such as a NUL
  /// shown as '?', at most 500 characters: room for the list of commands),
  /// whatever the script held.
  ScriptError(const std::string& file, int line, const std::string& message)
      : std::runtime_error(file + ":" + std::to_string(line) + ": " + first_line(message, 500)), line_(line) {}
  int line() const { return line_; }

 private:
  int line_;
};

/// Parses a script; `file` names it in errors. Blank lines and lines
/// starting with '#' are skipped. Checks every command's arguments (counts,
/// integers, option keys and values, structure names, camera syntax) and
/// throws ScriptError at the first bad line.
std::vector<ScriptCommand> parse_script(std::string_view text, const std::string& file);
/// Reads and parses a file (ScriptError "FILE:0: cannot be read" when missing).
std::vector<ScriptCommand> load_script(const std::filesystem::path& path);

/// Carries commands out. `execute` is called once per frame for the command
/// at hand until it returns done; it throws (any std::exception) to fail the
/// script with that message.
class ScriptHost {
 public:
  enum class Status { done, again };
  virtual ~ScriptHost() = default;
  virtual Status execute(const ScriptCommand& command) = 0;
};

class ScriptRunner {
 public:
  enum class State { running, finished, failed };

  /// `timeout_s`: a command still answering "again" after this long (a
  /// `wait` on a build that never ends) fails the script.
  ScriptRunner(std::vector<ScriptCommand> commands, std::string file, double timeout_s = 300.0);

  /// Runs commands until one needs another frame, the script ends (`quit`
  /// or the last line) or a command fails. `now_s` is a monotonic clock in
  /// seconds (passed in so the sequencing is testable without sleeping).
  State advance(ScriptHost& host, double now_s);

  State state() const { return state_; }
  /// "FILE:LINE: message" once failed.
  const std::string& error() const { return error_; }
  /// Index of the next command to run.
  std::size_t position() const { return next_; }

 private:
  std::vector<ScriptCommand> commands_;
  std::string file_;
  double timeout_s_;
  std::size_t next_ = 0;
  bool started_ = false;  ///< the command at next_ has been tried before
  double started_at_ = 0.0;
  State state_ = State::running;
  std::string error_;
};

}  // namespace accelviz
