#pragma once
// What the user chooses in the app, as plain values: the structure with
// every option of every type, the query choices, and the view layers. One
// table of named options ("buckets", "metric", "boxes", ...) reads and
// writes all of it as text, so the Structure/View panels, the script
// command `set KEY VALUE`, the settings file and the screenshot side-car
// agree on names and ranges by construction.
//
// GL-free (no GL, GLFW or ImGui): unit-tested without a window.
#include "core/accel/factory.h"
#include "core/analysis/colormap.h"
#include "core/analysis/heatmap.h"
#include "core/scene/effects.h"

#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace accelviz {

/// The structure to build and how to query it.
struct StructureChoice {
  std::string name = "bvh";  ///< one of structure_names()
  StructureOptions options;  ///< every type's options; only `name`'s are read by the build
  QueryOptions query;        ///< triangle test, ordered traversal (no rebuild needed)
};

enum class HeatmapDisplay { off, full_screen, blend };
enum class BoxMode { depth, depth_range, leaves, subtree };
enum class BoxColorBy { depth, sah_share };
/// Which level of a two-level structure (`tlas`) the node boxes show.
enum class BoxLevel {
  tlas,  ///< the top-level nodes (and each instance's world box as their leaves)
  blas,  ///< the bottom-level nodes of each instance, carried to world space
};

/// The renderer's layers as the user sets them (the GUI maps this onto
/// ui/render's RenderView; kept separate so this file needs no GL header).
struct ViewSettings {
  bool show_mesh = true;
  bool show_wireframe = false;

  bool show_boxes = true;
  BoxMode box_mode = BoxMode::depth;
  int box_depth = 3;       ///< depth mode: the depth; range mode: the first depth
  int box_depth_last = 5;  ///< range mode: the last depth (inclusive)
  /// Range mode's last depth as drawn: a last depth set below the first one
  /// (a script or settings file can) draws the first depth alone.
  int box_range_last() const { return box_depth_last < box_depth ? box_depth : box_depth_last; }
  int box_node = 0;        ///< subtree mode: its root node (the "selected node")
  BoxColorBy box_color = BoxColorBy::depth;
  bool boxes_through_mesh = false;
  BoxLevel box_level = BoxLevel::tlas;  ///< tlas only: top-level or bottom-level boxes
  int box_instance = -1;                ///< tlas, blas level: only this instance's BLAS boxes (-1: every instance)
  /// tlas only: each instance's triangles (and its boxes) in its own colour,
  /// hashed from the instance id.
  bool instance_colors = false;

  HeatmapDisplay heatmap = HeatmapDisplay::off;
  HeatMetric metric = HeatMetric::nodes;
  bool heatmap_gpu = false;      ///< trace the heatmap on the GPU (compute shader; BVH only, else the CPU worker)
  float heatmap_gpu_ms = 12.0f;  ///< GPU heatmap: tracing per frame, in row bands (0: one 8-row band a frame)
  ColorMap colormap = ColorMap::viridis;
  float opacity = 0.6f;    ///< blend: heatmap alpha over the mesh
  bool auto_scale = true;  ///< [0, image max]; else [scale_min, scale_max]
  float scale_min = 0.0f;
  float scale_max = 100.0f;
  bool show_legend = true;

  bool show_ray_path = true;
  int msaa = 4;  ///< samples of the 3D view (1 = off)
};

/// Everything the option table covers.
struct AppConfig {
  StructureChoice structure;
  ViewSettings view;
  /// Effects the user forced on in the Scene panel (ui/app/dynamics.h
  /// force_effect); not in the option table or the settings file.
  EffectForces effects;
};

/// One named option.
struct OptionInfo {
  std::string_view key;     ///< "buckets"
  std::string_view values;  ///< what it accepts, for help texts: "2..256"
  std::string_view help;    ///< one line
};

/// Every option key, in the order the docs and the settings file list them.
const std::vector<OptionInfo>& option_table();

/// Sets one option from text. Returns an empty string on success, else a
/// one-line message naming the key and what it accepts ("buckets: expected
/// an integer in 2..256, got 'x'"); `config` is unchanged on error.
std::string apply_option(AppConfig& config, std::string_view key, std::string_view value);

/// The current value of one option as text that apply_option accepts
/// (empty for an unknown key).
std::string option_value(const AppConfig& config, std::string_view key);

/// Every option as (key, value), in table order.
std::vector<std::pair<std::string, std::string>> option_values(const AppConfig& config);

/// The keys that configure structure `name` (its build options, in table
/// order, without the shared query options).
std::vector<std::string_view> structure_option_keys(std::string_view name);

/// Whether two choices build the same structure (name and that type's
/// options; query options and other types' options are ignored).
bool same_build(const StructureChoice& a, const StructureChoice& b);

/// "bvh (splitter=binned, buckets=16, leaf=4, ...)": the structure and its
/// own options, for captions and status lines.
std::string describe_structure(const StructureChoice& choice);

/// The caption under a screenshot: structure and options, triangle test,
/// ordering, and what the heatmap shows (metric, colour map, scale).
std::string screenshot_caption(const AppConfig& config);

/// The current view's heatmap as core's options at W×H: the View's metric,
/// the structure choice's query options and threads, and the cost metric's
/// weights (the BVH's C_trav/C_isect, as `render --ctrav/--cisect`). The
/// heatmap request, its restart key and the GPU trace all start from it.
HeatmapOptions view_heatmap_options(const AppConfig& config, int width, int height);

/// Text of a number as the option table writes it: shortest form that reads
/// back to the same float ("1", "0.25", "1e-05").
std::string format_number(double v);

}  // namespace accelviz
