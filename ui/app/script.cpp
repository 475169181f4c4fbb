#include "ui/app/script.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>

#include "core/accel/factory.h"
#include "core/analysis/heatmap.h"
#include "core/util/file_checks.h"
#include "ui/app/app_config.h"
#include "ui/app/dynamics.h"
#include "ui/app/flatten_worker.h"
#include "ui/app/scenarios.h"
#include "ui/app/sweep_worker.h"
#include "ui/app/window_titles.h"

namespace accelviz {
namespace {

std::string_view trim(std::string_view s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string_view::npos) return {};
  const auto e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

// Splits off the first word; `rest` gets the trimmed remainder.
std::string_view first_word(std::string_view s, std::string_view& rest) {
  const auto sp = s.find_first_of(" \t");
  if (sp == std::string_view::npos) {
    rest = {};
    return s;
  }
  rest = trim(s.substr(sp));
  return s.substr(0, sp);
}

bool parse_int(std::string_view s, int& out) {
  const auto r = std::from_chars(s.data(), s.data() + s.size(), out);
  return !s.empty() && r.ec == std::errc() && r.ptr == s.data() + s.size();
}

// `camera` takes what `accelviz render --camera` takes, minus the empty
// default: "ex,ey,ez,tx,ty,tz[,fov]" or "gltf:N". Whether gltf:N exists is
// only known once the scene is loaded.
std::string check_camera_spec(std::string_view spec) {
  if (spec.rfind("gltf:", 0) == 0) {
    int n = 0;
    if (!parse_int(spec.substr(5), n) || n < 0) return "camera: expected gltf:N with N >= 0";
    return {};
  }
  std::vector<float> v;
  std::string_view rest = spec;
  while (!rest.empty()) {
    const auto comma = rest.find(',');
    const std::string_view part = trim(rest.substr(0, comma));
    float f = 0.0f;
    const auto r = std::from_chars(part.data(), part.data() + part.size(), f);
    if (part.empty() || r.ec != std::errc() || r.ptr != part.data() + part.size() || !std::isfinite(f))
      return "camera: expected ex,ey,ez,tx,ty,tz[,fov] or gltf:N, got '" + std::string(spec) + "'";
    v.push_back(f);
    if (comma == std::string_view::npos) break;
    rest = rest.substr(comma + 1);
  }
  if (v.size() != 6 && v.size() != 7)
    return "camera: expected 6 or 7 numbers (eye, target, optional fov in degrees), got " + std::to_string(v.size());
  if (v[0] == v[3] && v[1] == v[4] && v[2] == v[5]) return "camera: eye and target are the same point";
  if (v.size() == 7 && !(v[6] > 0.0f && v[6] < 180.0f)) return "camera: fov must lie strictly between 0 and 180";
  return {};
}

struct NamedKind {
  std::string_view name;
  ScriptCommand::Kind kind;
};
constexpr NamedKind kCommands[] = {
    {"open", ScriptCommand::Kind::open},
    {"structure", ScriptCommand::Kind::structure},
    {"set", ScriptCommand::Kind::set},
    {"camera", ScriptCommand::Kind::camera},
    {"size", ScriptCommand::Kind::size},
    {"wait", ScriptCommand::Kind::wait},
    {"click", ScriptCommand::Kind::click},
    {"step", ScriptCommand::Kind::step},
    {"screenshot", ScriptCommand::Kind::screenshot},
    {"dump-ray", ScriptCommand::Kind::dump_ray},
    {"dump-stats", ScriptCommand::Kind::dump_stats},
    {"quit", ScriptCommand::Kind::quit},
    {"scenario", ScriptCommand::Kind::scenario},
    {"dump-scenario", ScriptCommand::Kind::dump_scenario},
    {"dump-insight", ScriptCommand::Kind::dump_insight},
    {"force-effect", ScriptCommand::Kind::force_effect},
    {"play", ScriptCommand::Kind::play},
    {"dump-dynamics", ScriptCommand::Kind::dump_dynamics},
    {"select-region", ScriptCommand::Kind::select_region},
    {"pin-a", ScriptCommand::Kind::pin_a},
    {"dump-ab", ScriptCommand::Kind::dump_ab},
    {"frames", ScriptCommand::Kind::frames},
    {"flatten", ScriptCommand::Kind::flatten},
    {"flatten-commit", ScriptCommand::Kind::flatten_commit},
    {"dump-flatten", ScriptCommand::Kind::dump_flatten},
    {"reload-shaders", ScriptCommand::Kind::reload_shaders},
    {"window", ScriptCommand::Kind::window},
    {"sweep", ScriptCommand::Kind::sweep},
    {"dump-sweep", ScriptCommand::Kind::dump_sweep},
    {"robustness", ScriptCommand::Kind::robustness},
    {"dump-robustness", ScriptCommand::Kind::dump_robustness},
    {"cancel", ScriptCommand::Kind::cancel},
};

}  // namespace

std::string_view command_name(ScriptCommand::Kind kind) {
  for (const NamedKind& c : kCommands)
    if (c.kind == kind) return c.name;
  return "?";
}

std::vector<std::string_view> script_command_names() {
  std::vector<std::string_view> names;
  for (const NamedKind& c : kCommands) names.push_back(c.name);
  return names;
}

std::vector<ScriptCommand> parse_script(std::string_view text, const std::string& file) {
  std::vector<ScriptCommand> out;
  // `set` values are checked against a scratch configuration that follows
  // the script's own `set`/`structure` lines, so "leaf-cap 2" after "leaf 8"
  // is caught here, with its line number, rather than mid-run.
  AppConfig scratch;
  int line_no = 0;
  std::size_t pos = 0;
  if (text.starts_with("\xEF\xBB\xBF")) pos = 3;  // a UTF-8 byte order mark is not part of the first command
  while (pos <= text.size()) {
    const auto nl = text.find('\n', pos);
    const std::string_view raw = text.substr(pos, nl == std::string_view::npos ? std::string_view::npos : nl - pos);
    pos = nl == std::string_view::npos ? text.size() + 1 : nl + 1;
    ++line_no;
    const std::string_view line = trim(raw);
    if (line.empty() || line.front() == '#') continue;

    auto fail = [&](const std::string& msg) { throw ScriptError(file, line_no, msg); };
    std::string_view rest;
    const std::string_view word = first_word(line, rest);
    const auto it =
        std::find_if(std::begin(kCommands), std::end(kCommands), [&](const NamedKind& c) { return c.name == word; });
    if (it == std::end(kCommands)) {
      std::string valid;
      for (const std::string_view name : script_command_names())
        valid += (valid.empty() ? "" : ", ") + std::string(name);
      // The word as written, at most 40 characters of it: the list of commands is what the line is for.
      const std::string said = word.size() > 40 ? std::string(word.substr(0, 40)) + "..." : std::string(word);
      fail("unknown command '" + said + "' (valid: " + valid + ")");
    }

    ScriptCommand c;
    c.kind = it->kind;
    c.line = line_no;
    c.text = std::string(line);
    const std::string name(word);
    auto need_rest = [&](const char* what) {
      if (rest.empty()) fail(name + ": expected " + what);
    };
    auto no_rest = [&] {
      if (!rest.empty()) fail(name + ": takes no argument");
    };
    switch (c.kind) {
      case ScriptCommand::Kind::open:
      case ScriptCommand::Kind::screenshot:
      case ScriptCommand::Kind::dump_ray:
      case ScriptCommand::Kind::dump_stats:
      case ScriptCommand::Kind::dump_scenario:
      case ScriptCommand::Kind::dump_insight:
      case ScriptCommand::Kind::dump_dynamics:
      case ScriptCommand::Kind::dump_ab:
      case ScriptCommand::Kind::dump_flatten:
      case ScriptCommand::Kind::dump_sweep:
      case ScriptCommand::Kind::dump_robustness:
        // The rest of the line, so paths may hold spaces.
        need_rest(c.kind == ScriptCommand::Kind::open ? "a scene (file or builtin:NAME)" : "a file path");
        c.arg = std::string(rest);
        if (c.kind == ScriptCommand::Kind::screenshot)
          if (const std::string problem = png_name_problem(c.arg); !problem.empty()) fail("screenshot: " + problem);
        break;
      case ScriptCommand::Kind::structure: {
        need_rest("a structure name");
        c.arg = std::string(rest);
        const std::string error = apply_option(scratch, "structure", c.arg);
        if (!error.empty()) fail(error);
        break;
      }
      case ScriptCommand::Kind::set: {
        need_rest("KEY VALUE");
        std::string_view value;
        const std::string_view key = first_word(rest, value);
        if (value.empty()) fail("set " + std::string(key) + ": expected a value");
        c.arg = std::string(key);
        c.value = std::string(value);
        const std::string error = apply_option(scratch, c.arg, c.value);
        if (!error.empty()) fail(error.rfind("unknown option", 0) == 0 ? "set: " + error : "set " + error);
        break;
      }
      case ScriptCommand::Kind::camera: {
        need_rest("ex,ey,ez,tx,ty,tz[,fov] or gltf:N");
        c.arg = std::string(rest);
        const std::string error = check_camera_spec(c.arg);
        if (!error.empty()) fail(error);
        break;
      }
      case ScriptCommand::Kind::size:
      case ScriptCommand::Kind::click: {
        std::string_view second;
        const std::string_view first = first_word(rest, second);
        std::string_view extra;
        const std::string_view second_word = first_word(second, extra);
        const bool is_size = c.kind == ScriptCommand::Kind::size;
        if (!parse_int(first, c.x) || !parse_int(second_word, c.y) || !extra.empty())
          fail(name + (is_size ? ": expected W H (two integers)" : ": expected X Y (two integers)"));
        if (is_size && (c.x < 64 || c.y < 64 || c.x > 8192 || c.y > 8192)) fail("size: W and H must lie in 64..8192");
        if (!is_size && (c.x < 0 || c.y < 0)) fail("click: X and Y must be >= 0");
        break;
      }
      case ScriptCommand::Kind::step: {
        need_rest("N, next, prev, first or last");
        c.arg = std::string(rest);
        int n = 0;
        if (c.arg != "next" && c.arg != "prev" && c.arg != "first" && c.arg != "last" &&
            !(parse_int(c.arg, n) && n >= 0))
          fail("step: expected N (>= 0), next, prev, first or last, got '" + c.arg + "'");
        break;
      }
      case ScriptCommand::Kind::select_region: {
        int v[4] = {0, 0, 0, 0};
        std::string_view left = rest;
        for (int& x : v) {
          std::string_view after;
          const std::string_view w = first_word(left, after);
          if (!parse_int(w, x) || x < 0) fail("select-region: expected X0 Y0 X1 Y1 (four integers >= 0)");
          left = after;
        }
        if (!left.empty()) fail("select-region: expected X0 Y0 X1 Y1 (four integers >= 0)");
        if (v[0] == v[2] || v[1] == v[3]) fail("select-region: the rectangle is empty");
        c.x = v[0];
        c.y = v[1];
        c.x2 = v[2];
        c.y2 = v[3];
        break;
      }
      case ScriptCommand::Kind::wait:
      case ScriptCommand::Kind::quit:
      case ScriptCommand::Kind::pin_a:
      case ScriptCommand::Kind::flatten_commit:
        no_rest();
        break;
      case ScriptCommand::Kind::reload_shaders:
        c.arg = std::string(rest);  // optional: the folder whose files win over the built-in shaders
        break;
      case ScriptCommand::Kind::sweep:
        // Checked against the structure the script has chosen by then, as the panel's Run does.
        need_rest("parameters, e.g. buckets=2,8 leaf=1,4");
        c.arg = std::string(rest);
        try {
          (void)parse_sweep_params_text(scratch.structure.name, c.arg);
        } catch (const std::invalid_argument& e) {
          fail("sweep: " + std::string(e.what()));
        }
        break;
      case ScriptCommand::Kind::flatten:
        // The ids are checked against the scene's instance count when it runs.
        need_rest("instance ids, e.g. 0,2,5-9 or all");
        c.arg = std::string(rest);
        try {
          check_instance_ids(c.arg);
        } catch (const std::invalid_argument& e) {
          fail("flatten: " + std::string(e.what()));
        }
        break;
      case ScriptCommand::Kind::force_effect: {
        std::string_view value;
        const std::string_view effect = first_word(rest, value);
        if (effect.empty()) fail("force-effect: expected NAME [on|off]");
        c.arg = std::string(effect);
        c.value = value.empty() ? "on" : std::string(value);
        if (c.value != "on" && c.value != "off") fail("force-effect: expected on or off, got '" + c.value + "'");
        AppConfig probe;
        const std::string error = force_effect(probe, c.arg, true);
        if (!error.empty()) fail(error);
        break;
      }
      case ScriptCommand::Kind::window: {
        std::string_view title;
        const std::string_view action = first_word(rest, title);
        if (action != "open" && action != "close") fail("window: expected open|close TITLE");
        c.value = std::string(action);
        c.arg = std::string(title);
        if (std::find(kPanelTitles.begin(), kPanelTitles.end(), title) == kPanelTitles.end()) {
          std::string valid;
          for (const std::string_view t : kPanelTitles) valid += (valid.empty() ? "" : ", ") + std::string(t);
          fail("window: no panel titled '" + c.arg + "' (valid: " + valid + ")");
        }
        break;
      }
      case ScriptCommand::Kind::play:
        if (!parse_int(rest, c.x) || c.x < 1 || c.x > 100000) fail("play: expected FRAMES (an integer in 1..100000)");
        break;
      case ScriptCommand::Kind::cancel:
        c.arg = std::string(rest);
        if (c.arg != "build" && c.arg != "sweep" && c.arg != "robustness")
          fail("cancel: expected build, sweep or robustness");
        break;
      case ScriptCommand::Kind::robustness:
        // The window's range (its Rays field); none: the window's count.
        if (!rest.empty() && (!parse_int(rest, c.x) || c.x < 4 || c.x > (1 << 22)))
          fail("robustness: expected N rays (an integer in 4..4194304) or nothing");
        break;
      case ScriptCommand::Kind::frames:
        if (!parse_int(rest, c.x) || c.x < 1 || c.x > 100000) fail("frames: expected N (an integer in 1..100000)");
        break;
      case ScriptCommand::Kind::scenario: {
        std::string_view value;
        const std::string_view id = first_word(rest, value);
        if (id.empty()) fail("scenario: expected NAME [VALUE]");
        const Scenario* sc = find_scenario(id);
        if (!sc) {
          std::string names;
          for (const Scenario& x : scenarios()) names += (names.empty() ? "" : ", ") + x.id;
          fail("scenario: unknown '" + std::string(id) + "' (valid: " + names + ")");
        }
        c.arg = std::string(id);
        c.value = value.empty() ? std::to_string(sc->initial) : std::string(value);
        char* end = nullptr;
        const float v = std::strtof(c.value.c_str(), &end);
        if (end == c.value.c_str() || *end != '\0' || !(v >= sc->min && v <= sc->max))
          fail("scenario " + c.arg + ": value '" + c.value + "' is not a number in " + std::to_string(sc->min) + ".." +
               std::to_string(sc->max));
        break;
      }
    }
    out.push_back(std::move(c));
  }
  return out;
}

std::vector<ScriptCommand> load_script(const std::filesystem::path& path) {
  // A regular file (a folder ran as an empty script, a FIFO would block) of
  // at most 16 MiB.
  std::string text;
  if (const std::string problem = read_text_file(path.string(), std::uintmax_t{16} << 20, text); !problem.empty())
    throw ScriptError(path.string(), 0, "cannot be read: " + problem);
  return parse_script(text, path.string());
}

ScriptRunner::ScriptRunner(std::vector<ScriptCommand> commands, std::string file, double timeout_s)
    : commands_(std::move(commands)), file_(std::move(file)), timeout_s_(timeout_s) {}

ScriptRunner::State ScriptRunner::advance(ScriptHost& host, double now_s) {
  while (state_ == State::running) {
    if (next_ >= commands_.size()) {
      state_ = State::finished;  // the end of the file quits, like `quit`
      break;
    }
    const ScriptCommand& c = commands_[next_];
    if (!started_) {
      started_ = true;
      started_at_ = now_s;
    }
    ScriptHost::Status status;
    try {
      status = host.execute(c);
    } catch (const std::exception& e) {
      std::string what = e.what();
      std::replace(what.begin(), what.end(), '\n', ' ');
      error_ = ScriptError(file_, c.line, std::string(command_name(c.kind)) + ": " + what).what();
      state_ = State::failed;
      break;
    }
    if (status == ScriptHost::Status::again) {
      if (now_s - started_at_ > timeout_s_) {
        error_ = ScriptError(file_, c.line,
                             std::string(command_name(c.kind)) + ": not complete after " +
                                 std::to_string(static_cast<int>(timeout_s_)) + " s")
                     .what();
        state_ = State::failed;
      }
      break;
    }
    started_ = false;
    ++next_;
    if (c.kind == ScriptCommand::Kind::quit) state_ = State::finished;
  }
  return state_;
}

}  // namespace accelviz
