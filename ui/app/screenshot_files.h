#pragma once
// Screenshot files: where they go, what they are called, the caption line
// drawn under the picture and the JSON side-car that says how to reproduce
// it. GL-free: the GUI hands over the frame it read back from the renderer.
#include <ctime>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/analysis/caption.h"
#include "core/analysis/heatmap.h"
#include "core/scene/scene.h"
#include "ui/app/app_config.h"

namespace accelviz {

/// $XDG_PICTURES_DIR/accelviz when XDG_PICTURES_DIR is set and absolute,
/// else $HOME/Pictures/accelviz.
std::filesystem::path default_screenshot_dir();

/// "YYYYmmdd-HHMMSS" in local time.
std::string screenshot_timestamp(std::time_t t);

struct ScreenshotPaths {
  std::filesystem::path png;
  std::filesystem::path json;  ///< the side-car: same stem, .json
};
/// "accelviz-STAMP.png" / ".json" in `dir`, or with "-2", "-3", ... appended:
/// the first stem for which neither file exists.
ScreenshotPaths unique_screenshot_paths(const std::filesystem::path& dir, const std::string& stamp);

/// What a screenshot shows, for its caption and side-car.
struct ScreenshotInfo {
  std::string scene;  ///< scene spec (file path or builtin:...)
  std::uint64_t triangles = 0;
  std::string camera_spec;  ///< ViewCamera::spec(): "" (scene default), "gltf:N" or "ex,ey,ez,tx,ty,tz,fov"
  Camera camera;            ///< the camera itself
  int width = 0;            ///< the 3D view's size in pixels (without the caption strip)
  int height = 0;
  AppConfig config;        ///< structure, options, view layers
  float scale_min = 0.0f;  ///< the heatmap range actually drawn
  float scale_max = 1.0f;
  std::optional<std::pair<int, int>> ray_pixel;  ///< the inspected pixel, when a ray is shown
  Camera ray_camera;  ///< the camera that pixel's ray was cast from (the view may have moved since)
  /// The ray's replay when it stops before the traversal's end: the step
  /// shown (0-based) and the steps in all.
  std::optional<std::size_t> ray_step;
  std::size_t ray_steps = 0;
  /// The node-box overlay as drawn: boxes drawn and boxes the selection
  /// names (more when the window cut the list and thinned it; 0 and 0
  /// without boxes).
  std::uint64_t boxes_drawn = 0, boxes_matched = 0;
  /// Boxes of a selected subtree: what its node id names and, when it was
  /// set in an earlier build, that build ("" otherwise).
  std::string box_node_note;
  /// The Predicted vs measured view drew the boxes: a heatmap region's
  /// entered nodes instead of the selection, or colours by visits. Neither is
  /// a view setting, so the side-car's script does not bring them back.
  bool boxes_of_region = false, boxes_by_visits = false;
  /// What made the picture, as the CLI's JSON names it: {version, commit,
  /// build_type, embree, line}, `line` being --version's ("accelviz 0.1.0
  /// (commit ..., Release build, ...)"), the PNG's Software text. Null leaves
  /// it out: a bug report's screenshot names the build it came from.
  nlohmann::json program;
};

/// screenshot_caption(info.config), ", boxes N of M" when the overlay
/// showed only N of the M boxes its selection names, and the subtree's node
/// note when boxes of a subtree are shown: the caption on the picture and in
/// its side-car.
std::string screenshot_caption(const ScreenshotInfo& info);

// wrap_caption, add_caption and kCaptionMaxLines: core/analysis/caption.h (render's captions too).
/// The side-car object (documented in docs/gui.md): scene, camera, size,
/// structure and options, query choices, heatmap settings and range, every
/// option, the caption, and the `accelviz render` and `accelviz --script`
/// lines that reproduce the picture.
nlohmann::json screenshot_sidecar(const ScreenshotInfo& info, const std::filesystem::path& png);

/// `accelviz render` command line for the heatmap (CPU) and raster (GL,
/// overlays) views of this screenshot; `notes` receives what the command
/// line cannot express (e.g. K-D tree options, a heatmap range not starting at 0).
std::string render_command(const ScreenshotInfo& info, bool raster, const std::string& out,
                           std::vector<std::string>* notes = nullptr);

struct SavedScreenshot {
  bool ok = false;
  std::filesystem::path png;
  std::filesystem::path json;
  std::string error;  ///< one line when !ok
};

/// Writes frame + caption and the side-car into `dir` (created if missing)
/// under a fresh time-stamped name. Files are created exclusively: a name
/// taken meanwhile moves on to the next one, nothing is ever overwritten.
SavedScreenshot save_screenshot(const std::filesystem::path& dir, const RgbImage& frame, const ScreenshotInfo& info,
                                std::time_t now);

/// The same to an explicit PNG path (scripts); the side-car is the path with
/// ".json". Refuses when either file exists.
SavedScreenshot save_screenshot_as(const std::filesystem::path& png, const RgbImage& frame, const ScreenshotInfo& info);

}  // namespace accelviz
