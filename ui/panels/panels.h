#pragma once
// The app's ImGui panels: thin free functions over explicit state. Each one
// draws its window and reports what the user changed (a bool "changed", or
// an action value); none of them builds, loads, traces or touches GL; the
// main loop (app/gui/) carries the actions out through AppState.
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/scene/scene.h"
#include "ui/app/app_config.h"
#include "ui/app/build_worker.h"
#include "ui/app/dynamics.h"
#include "ui/app/flatten_worker.h"
#include "ui/app/heatmap_worker.h"
#include "ui/app/ray_inspection.h"
#include "ui/app/robustness_worker.h"
#include "ui/app/settings.h"
#include "ui/app/structure_nodes.h"
#include "ui/app/sweep_worker.h"

namespace accelviz::panels {

/// Where panels start on first use (later the user's layout from imgui.ini wins).
struct PanelLayout {
  float scale = 1.0f;                      ///< HiDPI content scale
  float width = 1280.0f, height = 800.0f;  ///< window size in ImGui units
};

// ---- Scene ----------------------------------------------------------------------
struct SceneAction {
  std::optional<std::string> open;  ///< a scene to open (path field, built-in list, recent files)
  std::optional<int> camera;        ///< a scene camera chosen
  bool reset_view = false;
};
/// Path field with Open, the built-in scenes, recent files, and what the
/// shown scene holds (triangles, lights, its cameras).
SceneAction scene_panel(std::string& path_field, const std::vector<std::string>& recent, const Scene* scene,
                        const std::string& shown_spec, int active_camera, const PanelLayout& layout);

// ---- Structure --------------------------------------------------------------------
struct BuildProgress {
  bool busy = false;
  double fraction = 0.0;
  std::string stage;
  std::string shown;  ///< describe_structure() of the structure shown now
};
/// Type (every name the factory builds), every option of the chosen type,
/// the query choices, and the background build's progress with Cancel.
/// Returns true when `choice` changed; `cancel` is set when Cancel was pressed.
bool structure_panel(StructureChoice& choice, const BuildProgress& progress, bool& cancel, const PanelLayout& layout);

// ---- Stats ---------------------------------------------------------------------------
/// Build figures (BuildStats with its extras) of the structure shown, and
/// the current view's per-pixel figures from the heatmap pass.
void stats_panel(const BuiltStructure* built, const HeatmapFrame* view, const PanelLayout& layout);

// ---- View ------------------------------------------------------------------------------
struct ViewInfo {
  std::string node_kind;  ///< StructureNodes::kind() ("" when the structure has none)
  std::string structure;  ///< the shown structure's name ("" before one is built)
  std::string uncounted;  ///< the structure's name when it counts nothing per ray (embree), else ""
  std::uint32_t max_depth = 0;
  std::uint64_t node_count = 0;
  std::uint64_t boxes_drawn = 0;
  bool boxes_truncated = false;
  std::uint64_t boxes_matched = 0;           ///< boxes the selection names (more than drawn when cut)
  std::uint32_t blas_max_depth = 0;          ///< tlas: the deepest BLAS node (the blas level's depth range)
  std::uint64_t instances = 0;               ///< tlas: instances (the blas level's instance choice)
  float range_min = 0.0f, range_max = 1.0f;  ///< the heatmap range in use
  float value_min = 0.0f, value_max = 0.0f;  ///< the heatmap image's smallest and largest value
  bool heatmap_on_gpu = false;               ///< the heatmap shown was traced on the GPU
  std::string gpu_note;                      ///< why "Trace on: GPU" fell back to the CPU ("" when it did not)
  int gpu_rows_done = -1;                    ///< the GPU trace in progress: rows done (-1: none running)
  int gpu_rows = 0;                          ///< and rows in all
  std::string box_node_note;                 ///< subtree mode: what the node id names here (and where it was set)
};
/// Every renderer layer: mesh, wireframe, node boxes (selection, colouring),
/// heatmap (display, metric, colour map, scale, opacity, legend), ray path,
/// multisampling. Returns true when `view` changed.
/// `query` (optional): the heatmap section's traversal order (front-to-back,
/// back-to-front, unordered) and x-ray toggle, BVH only (a note elsewhere).
bool view_panel(ViewSettings& view, const ViewInfo& info, const PanelLayout& layout, QueryOptions* query = nullptr);

// ---- Ray -------------------------------------------------------------------------------
/// Origin, direction, hit, barycentrics, counters, shadow rays, and the
/// traversal as a list with step-through replay. Returns the replay step
/// the user moved to, if any.
std::optional<std::size_t> ray_panel(const RayInspection* ray, std::size_t step, const StructureNodes* nodes,
                                     const PanelLayout& layout);

// ---- Screenshot, help, status ---------------------------------------------------------------
/// Folder field, the Screenshot button and the last file written. True when pressed.
/// `folder` "" means `default_folder`.
bool screenshot_panel(std::string& folder, const std::string& default_folder, const std::string& last_written,
                      const PanelLayout& layout);
/// Every shortcut (ui/app/shortcuts.h).
void help_panel(bool& open, const PanelLayout& layout);
/// One line at the bottom: the error (red) or message, the build's progress,
/// and `heatmap_status` greyed after it ("" when the heatmap is done).
void status_bar(const std::string& message, const std::string& error, const BuildProgress& progress,
                const std::string& heatmap_status, const PanelLayout& layout);
/// The figures of one heatmap pixel, as a tooltip at the mouse.
/// The heatmap pixel under the mouse: its value (named in the structure's words: a grid's nodes are
/// cells), its counts and its hit.
void pixel_tooltip(int x, int y, const PixelFigures& p, HeatMetric metric, bool exact, std::string_view structure);

/// The width, in layout units, of the strip between the left and right columns where the insight
/// windows, the Ray and the Dynamics panels first open: 470 in a window 1280 wide or more, narrower
/// in a narrower one (a 1024-wide projector: 222) so that they do not cover the columns; at least 160.
float middle_width(const PanelLayout& layout);

/// A figure as panels print it: four significant digits, but whole up to 1e12 from 1e4 on (%.4g
/// printed 20000 prim tests as "2e+04").
std::string figure_text(double v);
/// Opens a panel's window: on first use placed at (x, y) (x < 0: from the
/// right edge) and sized w × h, in units the layout scales, and collapsed when
/// `collapsed`; then ImGui::Begin(title). False when the window is collapsed
/// or clipped: it is already ended and the panel returns.
bool begin_panel(const char* title, const PanelLayout& layout, float x, float y, float w, float h,
                 bool collapsed = false);
/// The same for the insight windows: on first use one title bar below the
/// other (`slot` 0, 1, ...) in the strip between the two columns, at most as
/// wide as that strip, so that collapsed they neither overlap each other nor
/// the columns.
bool begin_stacked_panel(const char* title, const PanelLayout& layout, int slot, float w, float h,
                         bool collapsed = true);
/// Expands (`open`) or collapses the panel titled `title` when it is next
/// drawn (a script's `window`; pin-a and scenario open their windows); an
/// opened panel comes to the front.
void request_window(std::string_view title, bool open);
/// True when the screen rectangle (x0, y0)-(x1, y1) (ImGui's units) overlaps a
/// top-level window drawn this frame, or last frame for one not yet drawn
/// in this one (a collapsed window by its title bar): what is drawn behind
/// the windows there would show through their translucent background.
bool covered_by_window(float x0, float y0, float x1, float y1);
/// A running job's row, from the cursor on: a progress bar `bar_width` wide
/// (an ImGui item width: -1 fills the row, -w leaves w at its right) showing
/// `fraction` and `overlay` (null: the percentage), with a Cancel button on
/// the same line before or after it. Returns true when Cancel was clicked.
enum class CancelAt { before, after };
bool progress_cancel_row(double fraction, const char* overlay, float bar_width, CancelAt cancel_at);

// ---- Cost of accuracy (accuracy_panel.cpp) -----------------------------------------------
struct AccuracyPanelState {
  std::string params;             ///< "buckets=2,4,exact leaf=1,4" (the structure's default when it changes)
  std::string params_for;         ///< structure `params` was made for
  int width = 160, height = 120;  ///< primary rays of the current view
  int repeat = 1;
  double ray_budget = 1e6;
  int figure = 0;  ///< SweepFigure of the figure-vs-parameter chart
  int param = 0;   ///< its parameter
  bool calibrate = false;
  bool collapsed_at_start = true;
  std::string error;  ///< the last request's one-line error (bad parameter)
};
struct AccuracyAction {
  bool run = false;  ///< run the sweep in `params` (restarting one in progress)
  bool cancel = false;
  std::optional<SweepSetting> apply;  ///< a clicked point's setting ...
  std::string apply_structure;        ///< ... for this structure
};
/// Parameter field, ray size, Run/Cancel with progress, and the live charts
/// of `snap` (build vs trace with the Pareto front, total for the ray budget,
/// figure vs parameter, table, calibrated constants).
AccuracyAction accuracy_panel(AccuracyPanelState& state, const SweepSnapshot* snap, bool busy,
                              const std::string& structure, const PanelLayout& layout);

// ---- Robustness (robustness_panel.cpp) ----------------------------------------------
struct RobustnessPanelState {
  int rays = 20000;
  bool with_structure = true;  ///< also the chosen structure's own traversal
  int variant = 3;             ///< the variant of the per-ray map (3: watertight + padded slab)
  bool collapsed_at_start = true;
};
struct RobustnessAction {
  bool run = false;
  bool cancel = false;
};
/// Rays field, Run/Cancel, the lab's variants side by side (misses, double
/// hits, wrong, ms, Mrays/s; by family in a tooltip) and a per-ray status map
/// of the selected variant.
RobustnessAction robustness_panel(RobustnessPanelState& state, const RobustnessSnapshot* snap, bool busy,
                                  const std::string& structure, const PanelLayout& layout);

// ---- Effects and Dynamics (dynamics_panel.cpp) ---------------------------------------
/// Appends the scene's effects to the Scene window: each effect on or off
/// with its reason, and a "force" checkbox. Returns (name, forced) when one
/// was ticked or unticked.
std::optional<std::pair<std::string, bool>> scene_effects_section(const SceneEffects* effects);
/// Play/pause, speed, the time slider, and the per-frame figures of `snap`
/// plotted over time (TLAS rebuild ms, refit ms, rebuild ms, SAH refitted
/// vs rebuilt).
void dynamics_panel(DynamicsPlayer& player, const DynamicsSnapshot* snap, bool busy, const PanelLayout& layout);

// ---- Flatten what-if (flatten_panel.cpp) ----------------------------------------------
struct FlattenPanelState {
  std::string ids;                              ///< the selection as typed ("0,2,5-9", "all")
  std::vector<std::uint32_t> selected;          ///< parsed, sorted, distinct
  std::string error;                            ///< the text's parse error
  int width = 160, height = 120;                ///< primary rays of the current view traced for the prediction
  const LoadedScene* scene_identity = nullptr;  ///< the scene the selection is of (results of others are hidden)
  bool collapsed_at_start = true;
};
struct FlattenAction {
  bool preview = false;  ///< measure the selection (restarting one in progress)
  bool commit = false;   ///< rebuild with the previewed selection merged
  bool cancel = false;
};
/// Sets the selection (ids sorted and distinct) and its text.
void set_flatten_selection(FlattenPanelState& state, std::vector<std::uint32_t> ids);
/// Instances field, "add clicked instance", a checkbox list, Predict/Cancel
/// with progress, the predicted figures (two-level vs flattened: nodes,
/// triangle tests, instances per ray, trace ms, memory, SAH, build ms) and
/// Commit, enabled once the shown prediction is of the current selection.
FlattenAction flatten_panel(FlattenPanelState& state, const Scene* scene, const FlattenResult* result, bool busy,
                            double fraction, std::optional<std::uint32_t> clicked_instance, const PanelLayout& layout);

}  // namespace accelviz::panels
