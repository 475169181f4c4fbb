#include "ui/app/screenshot_files.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <memory>

#include "core/util/json_text.h"
#include "core/util/output_file.h"
#include "core/util/shell_quote.h"
#include "ui/app/orbit_camera.h"

namespace accelviz {
namespace fs = std::filesystem;
namespace {

/// "K/LAST" as the Ray panel's slider reads a replay step (steps 0 to LAST; it said "K of N").
std::string replay_step_text(std::size_t step, std::size_t steps) {
  return std::to_string(step) + "/" + std::to_string(steps > 0 ? steps - 1 : 0);
}

}  // namespace

namespace {

std::string heatmap_display_name(HeatmapDisplay d) {
  switch (d) {
    case HeatmapDisplay::off:
      return "off";
    case HeatmapDisplay::full_screen:
      return "full";
    case HeatmapDisplay::blend:
      return "blend";
  }
  return "off";
}

// Writes the PNG and its side-car as one set (write_output_files): both or neither, each name
// taken exclusively; on a taken name the caller moves on. A side-car that failed (a full disk) left
// the PNG behind, and a script's rerun was then refused by it.
SavedScreenshot write_pair(const ScreenshotPaths& paths, const RgbImage& frame, const ScreenshotInfo& info,
                           bool* name_taken) {
  SavedScreenshot r;
  r.png = paths.png;
  r.json = paths.json;
  *name_taken = false;
  // Both names are checked before the work, so a taken one costs no encoding; the exclusive
  // creates below catch a late race.
  for (const fs::path& p : {paths.png, paths.json})
    if (accelviz::name_taken(p.string())) {
      *name_taken = true;
      r.error = p.string() + ": exists (not overwritten)";
      return r;
    }
  std::string png;
  try {
    // The whole caption in the file too (the picture's strip cuts it on a small window), and the build.
    std::vector<PngText> text{{"Description", screenshot_caption(info)}};
    if (info.program.is_object()) text.push_back({"Software", info.program.value("line", "")});
    png = encode_png(add_caption(frame, screenshot_caption(info)), paths.png.string(), text);
  } catch (const std::exception& e) {
    r.error = e.what();
    return r;
  }
  const OutputWrite w =
      write_output_files({{paths.png.string(), std::move(png)},
                          {paths.json.string(), json_text(screenshot_sidecar(info, paths.png), 2) + "\n"}},
                         /*overwrite=*/false);
  if (!w.ok()) {
    *name_taken = w.exists;
    r.error = w.path + ": " + (w.exists ? std::string("exists (not overwritten)") : w.problem);
    return r;
  }
  r.ok = true;
  return r;
}

}  // namespace

fs::path default_screenshot_dir() {
  if (const char* p = std::getenv("XDG_PICTURES_DIR"); p && *p == '/') return fs::path(p) / "accelviz";
  const char* home = std::getenv("HOME");
  return fs::path(home && *home ? home : ".") / "Pictures" / "accelviz";
}

std::string screenshot_timestamp(std::time_t t) {
  std::tm tm{};
  localtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y%m%d-%H%M%S", &tm);
  return buf;
}

ScreenshotPaths unique_screenshot_paths(const fs::path& dir, const std::string& stamp) {
  for (int k = 1;; ++k) {
    std::string stem = "accelviz-" + stamp;
    if (k > 1) {
      stem += '-';
      stem += std::to_string(k);
    }
    ScreenshotPaths p{dir / (stem + ".png"), dir / (stem + ".json")};
    std::error_code ec;
    if (!name_taken(p.png.string()) && !name_taken(p.json.string())) return p;
  }
}

/// The shown ray was cast from another view than the one shown (the camera moved after the click).
bool ray_from_another_view(const ScreenshotInfo& info) {
  return info.ray_pixel && explicit_camera_spec(info.ray_camera) != explicit_camera_spec(info.camera);
}

std::string render_command(const ScreenshotInfo& info, bool raster, const std::string& out,
                           std::vector<std::string>* notes) {
  const AppConfig& c = info.config;
  const StructureChoice& s = c.structure;
  std::string cmd = "accelviz render " + shell_quote(info.scene) + " --structure " + s.name;
  if (!info.camera_spec.empty()) cmd += " --camera " + shell_quote(info.camera_spec);
  cmd += " --size " + std::to_string(info.width) + "x" + std::to_string(info.height);
  cmd += " --metric " + std::string(metric_name(c.view.metric));
  cmd += " --colormap " + std::string(colormap_name(c.view.colormap));
  cmd += " --triangle-test " + option_value(c, "triangle-test");
  // The traversal's child order and x-ray counting (render's --order, --xray).
  const QueryOptions& q = s.query;
  if (!q.ordered)
    cmd += " --order unordered";
  else if (q.back_to_front)
    cmd += " --order back-to-front";
  if (q.xray) cmd += " --xray";
  if (!c.view.auto_scale) {
    cmd += " --max " + format_number(c.view.scale_max);
    if (notes && !raster && c.view.scale_min != 0.0f)
      notes->push_back("the heatmap range starts at " + format_number(c.view.scale_min) +
                       "; `render --max` always starts at 0");
  }
  // The BVH's options are command-line options of `render`; they also carry
  // the cost metric's weights for every structure.
  for (const char* key : {"splitter", "buckets", "leaf", "leaf-cap", "ctrav", "cisect"})
    cmd += std::string(" --") + key + " " + option_value(c, key);
  if (s.name == "embree") cmd += " --embree-quality " + option_value(c, "embree-quality");
  if (notes && !raster) {  // once: the heatmap's and the raster's commands share these
    const AppConfig defaults;
    for (std::string_view key : structure_option_keys(s.name)) {
      if (s.name == "bvh" || s.name == "tlas" || s.name == "embree") break;  // render takes these
      if (option_value(c, key) != option_value(defaults, key))
        notes->push_back(std::string(key) + "=" + option_value(c, key) +
                         " is not a command-line option of render (it builds " + s.name +
                         " with defaults): replay the `script` instead");
    }
  }
  if (raster) {
    cmd += " --view raster";
    const ViewSettings& v = c.view;
    if (v.show_boxes && s.name != "bvh") {
      // render --view raster draws a BVH's node boxes only (it refuses
      // --depth/--leaves for other structures); say so when boxes were drawn.
      if (notes && info.boxes_drawn > 0)
        notes->push_back("raster: the command line draws a BVH's node boxes only; the window's " + s.name +
                         " boxes are left out");
    } else if (v.show_boxes) {
      switch (v.box_mode) {
        case BoxMode::depth:
          cmd += " --depth " + std::to_string(v.box_depth);
          break;
        case BoxMode::depth_range:
          cmd += " --depth " + std::to_string(v.box_depth) + " --depth-last " + std::to_string(v.box_range_last());
          break;
        case BoxMode::leaves:
          cmd += " --leaves";
          break;
        case BoxMode::subtree:
          if (notes) notes->push_back("raster: a subtree selection has no command-line option");
          break;
      }
      if (notes && v.box_color != BoxColorBy::depth)
        notes->push_back("raster: boxes are coloured by depth on the command line");
      if (notes && info.boxes_drawn < info.boxes_matched)
        notes->push_back("raster: the window drew " + std::to_string(info.boxes_drawn) + " of the " +
                         std::to_string(info.boxes_matched) +
                         " boxes, spread evenly over the selection; the command line draws all");
    }
    if (notes && v.msaa > 1)
      notes->push_back("raster: the window drew with " + std::to_string(v.msaa) +
                       "x multisampling; render --view raster draws without (edges differ; `set msaa 1` in the window "
                       "draws as the command line does)");
    if (v.show_wireframe) cmd += " --wireframe";
    if (v.heatmap == HeatmapDisplay::blend) cmd += " --blend " + format_number(v.opacity);
    if (v.heatmap == HeatmapDisplay::full_screen) cmd += " --blend 1";
    if (info.ray_pixel && v.show_ray_path) {
      cmd += " --ray-pixel " + std::to_string(info.ray_pixel->first) + "," + std::to_string(info.ray_pixel->second);
      if (ray_from_another_view(info)) cmd += " --ray-camera " + shell_quote(explicit_camera_spec(info.ray_camera));
      if (notes && info.ray_step)
        notes->push_back("raster: --ray-pixel draws the whole traversal; the window showed its replay at step " +
                         replay_step_text(*info.ray_step, info.ray_steps) + " (the script's `step` brings that back)");
    }
  }
  return cmd + " --out " + shell_quote(out);
}

std::string screenshot_caption(const ScreenshotInfo& info) {
  // Which scene first: a teapot and a teapot in a stadium look alike (a file by its name only).
  std::string s = info.scene.starts_with("builtin:") ? info.scene : fs::path(info.scene).filename().string();
  s += (s.empty() ? "" : ", ") + screenshot_caption(info.config);
  if (info.config.view.heatmap != HeatmapDisplay::off)
    if (const std::string why = metric_not_counted(info.config.view.metric, info.config.structure.name); !why.empty())
      s += " (n/a: " + why + ")";
  if (info.boxes_drawn < info.boxes_matched)
    s += ", boxes " + std::to_string(info.boxes_drawn) + " of " + std::to_string(info.boxes_matched);
  if (info.boxes_of_region)
    s += ", boxes: the nodes a heatmap region's rays entered";
  else if (!info.box_node_note.empty())
    s += ", boxes of " + info.box_node_note;
  if (info.boxes_by_visits) s += ", coloured by visits";
  if (info.ray_pixel && info.config.view.show_ray_path) {
    s += ", ray of pixel " + std::to_string(info.ray_pixel->first) + "," + std::to_string(info.ray_pixel->second);
    if (ray_from_another_view(info)) s += " of an earlier view";
    if (info.ray_step) s += " at step " + replay_step_text(*info.ray_step, info.ray_steps);
  }
  return s;
}

nlohmann::json screenshot_sidecar(const ScreenshotInfo& info, const fs::path& png) {
  const AppConfig& c = info.config;
  nlohmann::json structure_options = nlohmann::json::object();
  for (std::string_view key : structure_option_keys(c.structure.name))
    structure_options[std::string(key)] = option_value(c, key);
  nlohmann::json all_options = nlohmann::json::object();
  for (const auto& [key, value] : option_values(c)) all_options[key] = value;

  const Camera& cam = info.camera;
  auto vec = [](const glm::vec3& v) { return nlohmann::json::array({v.x, v.y, v.z}); };

  std::vector<std::string> notes;
  const std::string stem = png.stem().string();
  const std::string heatmap_cmd = render_command(info, false, stem + "-heatmap.png", &notes);
  const std::string raster_cmd = render_command(info, true, stem + "-raster.png", &notes);
  if (info.boxes_of_region || info.boxes_by_visits)
    notes.push_back(std::string("boxes: ") +
                    (info.boxes_of_region ? "a heatmap region's entered nodes" : "coloured by visits") +
                    " (Predicted vs measured), which the script does not measure or select again");

  // A script replays the picture in the app itself, with every option.
  std::vector<std::string> script = {"open " + info.scene,
                                     "size " + std::to_string(info.width) + " " + std::to_string(info.height)};
  for (const auto& [key, value] : option_values(c)) script.push_back("set " + key + " " + value);
  const std::string click =
      info.ray_pixel ? "click " + std::to_string(info.ray_pixel->first) + " " + std::to_string(info.ray_pixel->second)
                     : std::string();
  if (ray_from_another_view(info)) {
    // The click first, from the view it was made in; then the view the picture shows.
    script.push_back("camera " + explicit_camera_spec(info.ray_camera));
    script.push_back("wait");
    script.push_back(click);
    script.push_back("camera " + (info.camera_spec.empty() ? explicit_camera_spec(info.camera) : info.camera_spec));
    script.push_back("wait");
  } else {
    if (!info.camera_spec.empty()) script.push_back("camera " + info.camera_spec);
    script.push_back("wait");
    if (info.ray_pixel) script.push_back(click);
  }
  if (info.ray_pixel && info.ray_step) script.push_back("step " + std::to_string(*info.ray_step));
  script.push_back("screenshot " + stem + "-replay.png");
  script.push_back("quit");

  nlohmann::json out = {
      {"png", fs::absolute(png).string()},
      {"caption", screenshot_caption(info)},
      {"boxes",
       {{"drawn", info.boxes_drawn},
        {"matched", info.boxes_matched},
        {"node_note", info.boxes_of_region ? std::string() : info.box_node_note},
        {"region", info.boxes_of_region},
        {"by_visits", info.boxes_by_visits}}},
      {"scene", info.scene},
      {"triangles", info.triangles},
      {"size", {{"width", info.width}, {"height", info.height}}},
      {"camera",
       {{"spec", info.camera_spec},
        {"eye", vec(cam.position)},
        {"forward", vec(cam.forward)},
        {"up", vec(cam.up)},
        {"yfov_deg", cam.yfov * 180.0 / 3.14159265358979}}},
      {"structure", {{"name", c.structure.name}, {"options", structure_options}}},
      {"query",
       {{"triangle_test", option_value(c, "triangle-test")},
        {"ordered", c.structure.query.ordered},
        {"back_to_front", c.structure.query.back_to_front},
        {"xray", c.structure.query.xray}}},
      {"heatmap",
       {{"display", heatmap_display_name(c.view.heatmap)},
        {"metric", metric_name(c.view.metric)},
        {"colormap", colormap_name(c.view.colormap)},
        {"scale", option_value(c, "scale")},
        {"range", {info.scale_min, info.scale_max}},
        {"opacity", c.view.opacity},
        {"legend", c.view.show_legend}}},
      {"options", all_options},
      {"ray_pixel", info.ray_pixel ? nlohmann::json::array({info.ray_pixel->first, info.ray_pixel->second})
                                   : nlohmann::json(nullptr)},
      {"ray_camera",
       ray_from_another_view(info) ? nlohmann::json(explicit_camera_spec(info.ray_camera)) : nlohmann::json(nullptr)},
      {"reproduce",
       {{"render_heatmap", heatmap_cmd}, {"render_raster", raster_cmd}, {"notes", notes}, {"script", script}}},
  };
  if (!info.program.is_null()) out["program"] = info.program;
  return out;
}

SavedScreenshot save_screenshot(const fs::path& dir, const RgbImage& frame, const ScreenshotInfo& info,
                                std::time_t now) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) return {false, {}, {}, dir.string() + ": " + ec.message()};
  const std::string stamp = screenshot_timestamp(now);
  // A name can be taken between the check and the exclusive create (another
  // instance, a second F12 in the same second): move on to the next one.
  for (int attempt = 0; attempt < 1000; ++attempt) {
    bool taken = false;
    SavedScreenshot r = write_pair(unique_screenshot_paths(dir, stamp), frame, info, &taken);
    if (r.ok || !taken) return r;
  }
  return {false, {}, {}, dir.string() + ": no free screenshot name"};
}

SavedScreenshot save_screenshot_as(const fs::path& png, const RgbImage& frame, const ScreenshotInfo& info) {
  fs::path json = png;
  json.replace_extension(".json");
  bool taken = false;
  return write_pair({png, json}, frame, info, &taken);
}

}  // namespace accelviz
