#include "ui/app/settings.h"

#include <algorithm>
#include <cstdlib>

#include "core/util/file_checks.h"
#include "core/util/json_text.h"
#include "core/util/output_file.h"

namespace accelviz {

void add_recent(AppSettings& s, const std::string& spec) {
  if (spec.empty()) return;
  s.recent.erase(std::remove(s.recent.begin(), s.recent.end(), spec), s.recent.end());
  s.recent.insert(s.recent.begin(), spec);
  if (s.recent.size() > AppSettings::kMaxRecent) s.recent.resize(AppSettings::kMaxRecent);
}

std::filesystem::path config_dir() {
  // The spec says a relative XDG_CONFIG_HOME is invalid and must be ignored.
  if (const char* xdg = std::getenv("XDG_CONFIG_HOME"); xdg && *xdg == '/')
    return std::filesystem::path(xdg) / "accelviz";
  const char* home = std::getenv("HOME");
  return std::filesystem::path(home && *home ? home : ".") / ".config" / "accelviz";
}

nlohmann::json settings_to_json(const AppSettings& s) {
  nlohmann::json options = nlohmann::json::object();
  for (const auto& [key, value] : option_values(s.config)) options[key] = value;
  return {{"version", 1},
          {"last_scene", s.last_scene},
          {"recent", s.recent},
          {"screenshot_dir", s.screenshot_dir},
          {"window", {{"width", s.window_width}, {"height", s.window_height}}},
          {"options", options},
          {"effects",
           {{"shadow-rays", s.config.effects.shadow_rays},
            {"per-frame-updates", s.config.effects.per_frame_updates},
            {"two-level", s.config.effects.two_level}}}};
}

AppSettings settings_from_json(const nlohmann::json& j) {
  using std::runtime_error;
  if (!j.is_object()) throw runtime_error("not a JSON object");
  AppSettings s;
  // get<long long>: get<int> cut 4294967297 down to 1.
  if (j.contains("version") && (!j["version"].is_number_integer() || j["version"].get<long long>() != 1))
    throw runtime_error("unsupported version " + j["version"].dump());
  // The keys settings_to_json writes (taken from it, so the two cannot
  // drift); anything else is a typo or another program's file, said rather
  // than ignored.
  const nlohmann::json known = settings_to_json(AppSettings{});
  const auto check_keys = [](const nlohmann::json& given, const nlohmann::json& valid, const std::string& where) {
    for (const auto& [key, value] : given.items())
      if (!valid.contains(key)) {
        std::string names;
        for (const auto& [k, v] : valid.items()) names += (names.empty() ? "" : ", ") + k;
        throw runtime_error(where + "unknown key '" + key + "' (valid: " + names + ")");
      }
  };
  check_keys(j, known, "");
  auto string_field = [&](const char* key, std::string& out) {
    if (!j.contains(key)) return;
    if (!j[key].is_string()) throw runtime_error(std::string(key) + ": expected a string");
    out = j[key].get<std::string>();
  };
  string_field("last_scene", s.last_scene);
  string_field("screenshot_dir", s.screenshot_dir);
  if (j.contains("recent")) {
    if (!j["recent"].is_array()) throw runtime_error("recent: expected an array of strings");
    for (const auto& r : j["recent"]) {
      if (!r.is_string()) throw runtime_error("recent: expected an array of strings");
      if (s.recent.size() < AppSettings::kMaxRecent) s.recent.push_back(r.get<std::string>());
    }
  }
  if (j.contains("window")) {
    const auto& w = j["window"];
    if (!w.is_object()) throw runtime_error("window: expected an object with width and height");
    check_keys(w, known["window"], "window: ");
    // At most 8192: a 16384-pixel window's multisampled target was incomplete on llvmpipe.
    auto side = [&](const char* key, int& out) {
      if (!w.contains(key)) return;
      if (!w[key].is_number_integer() || w[key].get<long long>() < 100 || w[key].get<long long>() > 8192)
        throw runtime_error(std::string("window.") + key + ": expected an integer in 100..8192");
      out = w[key].get<int>();
    };
    side("width", s.window_width);
    side("height", s.window_height);
  }
  if (j.contains("effects")) {  // the Scene panel's force-on checkboxes
    const auto& e = j["effects"];
    if (!e.is_object()) throw runtime_error("effects: expected an object");
    for (const auto& [name, on] : e.items()) {
      bool* force = name == "shadow-rays"         ? &s.config.effects.shadow_rays
                    : name == "per-frame-updates" ? &s.config.effects.per_frame_updates
                    : name == "two-level"         ? &s.config.effects.two_level
                                                  : nullptr;
      if (!force)
        throw runtime_error("effects." + name + ": unknown effect (valid: shadow-rays, per-frame-updates, two-level)");
      if (!on.is_boolean()) throw runtime_error("effects." + name + ": expected true or false");
      *force = on.get<bool>();
    }
  }
  if (j.contains("options")) {
    const auto& o = j["options"];
    if (!o.is_object()) throw runtime_error("options: expected an object");
    // "structure" first: nothing else depends on it, but "leaf" before
    // "leaf-cap" matters, and table order guarantees that; iterate the table.
    for (const OptionInfo& info : option_table()) {
      const auto it = o.find(std::string(info.key));
      if (it == o.end()) continue;
      if (!it->is_string()) throw runtime_error("options." + std::string(info.key) + ": expected a string");
      const std::string error = apply_option(s.config, info.key, it->get<std::string>());
      if (!error.empty()) throw runtime_error("options." + error);
    }
    for (const auto& item : o.items()) {
      const std::string& key = item.key();
      const auto& table = option_table();
      if (std::none_of(table.begin(), table.end(), [&](const OptionInfo& i) { return i.key == key; }))
        throw runtime_error("options: unknown option '" + key + "'");
    }
  }
  return s;
}

LoadedSettings load_settings(const std::filesystem::path& file) {
  LoadedSettings out;
  // A regular file of at most 1 MiB (a few KB in use): a FIFO would block the
  // app's start and a huge file would be read whole.
  std::string text;
  if (const std::string problem = read_text_file(file.string(), kMaxSettingsBytes, text); !problem.empty()) {
    if (problem != "no such file") {
      // Not read, so not copied: a save would replace what the user has there.
      out.leave_file = true;
      out.error = file.string() + ": " + problem +
                  " (using defaults; the file is left as it is: settings are not saved this session)";
    }
    return out;
  }
  try {
    out.settings = settings_from_json(nlohmann::json::parse(text));
  } catch (const std::exception& e) {
    std::string what = e.what();
    std::replace(what.begin(), what.end(), '\n', ' ');
    out.settings = AppSettings{};
    // The defaults replace the file at the next save: its recent list, folders and window size
    // would be lost for one bad value, so a copy is kept first under a fresh name.
    // Up to 1,000 names, each taken or failing (a folder has the name); a full disk fails them all,
    // so the failures stop at 20.
    std::string kept, first_problem;
    for (int k = 1, failures = 0; k <= 1000 && kept.empty() && failures < 20; ++k) {
      const std::filesystem::path copy = file.string() + (k == 1 ? ".bad" : ".bad-" + std::to_string(k));
      const OutputWrite w = write_output_file(copy.string(), {text}, /*overwrite=*/false);
      if (w.ok()) {
        kept = "the file is kept as " + copy.string();
      } else if (!w.exists) {
        ++failures;
        if (first_problem.empty()) first_problem = copy.string() + ": " + w.problem;
      }
    }
    out.leave_file = kept.empty();
    out.error = file.string() + ": " + what + " (using defaults; " +
                (kept.empty() ? "no copy kept" + (first_problem.empty() ? std::string() : ": " + first_problem) +
                                    ", so the file is left as it is: settings are not saved this session"
                              : kept) +
                ")";
  }
  return out;
}

std::string write_file_atomic(const std::filesystem::path& file, std::string_view content) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path dir = file.has_parent_path() ? file.parent_path() : fs::path(".");
  fs::create_directories(dir, ec);
  if (ec) return dir.string() + ": " + ec.message();
  // A fresh temporary in the same folder, flushed, then renamed over the
  // file (write_output_file): a crash or a full disk keeps the old settings.
  const OutputWrite w = write_output_file(file.string(), {content}, /*overwrite=*/true);
  return w.ok() ? std::string() : file.string() + ": " + w.problem;
}

std::string write_new_file(const std::filesystem::path& file, std::string_view content) {
  const OutputWrite w = write_output_file(file.string(), {content}, /*overwrite=*/false);
  if (w.exists) return file.string() + ": exists (not overwritten)";
  return w.ok() ? std::string() : file.string() + ": " + w.problem;
}

std::string save_settings(const std::filesystem::path& file, const AppSettings& s) {
  return write_file_atomic(file, json_text(settings_to_json(s), 2) + "\n");
}

}  // namespace accelviz
