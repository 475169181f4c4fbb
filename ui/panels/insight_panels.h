#pragma once
// The insight panels (insight_panels.cpp, scenarios_panel.cpp): A/B
// comparison, predicted vs measured cost with hot nodes and traversal modes,
// the binned-SAH explainer, the tree view and the lecture scenarios. Thin
// functions over state, like panels.h; the work runs in ui/app/insight_jobs.h
// and ui/app/scenarios.h.
#include <cstdint>
#include <optional>
#include <string>

#include "core/analysis/insight/sah_explainer.h"
#include "ui/app/hot_nodes.h"
#include "ui/app/insight_jobs.h"
#include "ui/app/scenarios.h"
#include "ui/panels/panels.h"

namespace accelviz::panels {

// ---- A/B ------------------------------------------------------------------------------
struct ABPanelState {
  std::optional<StructureChoice> pinned;  ///< A
  int display = 0;                        ///< 0 side by side, 1 split, 2 difference
  float split = 0.5f;                     ///< split: fraction of the width showing A
  int metric = 0;                         ///< 0 nodes, 1 prims, 2 cost
  int width = 96, height = 72;
};
struct ABAction {
  bool pin = false;      ///< pin the current choice as A
  bool compare = false;  ///< run A vs the current choice (B)
};
ABAction ab_panel(ABPanelState& state, const ABResult* result, bool busy, const std::string& error,
                  const StructureChoice& current, const PanelLayout& layout);

// ---- Predicted vs measured, hot nodes, traversal modes ----------------------------------
struct InsightPanelState {
  bool hot_boxes = true;            ///< colour the 3D view's boxes by visits
  int labels = 5;                   ///< label the selected node and this many hot nodes in the 3D view
  bool click_selects_leaf = true;   ///< a click in the 3D view selects the leaf its hit lies in
  std::optional<PixelRect> region;  ///< selected pixels of the record (drag on the image)
  bool dragging = false;
  int drag_x = 0, drag_y = 0;  ///< record pixel where the drag started
  float image_x = 0.0f, image_y = 0.0f, image_cell = 0.0f;  ///< where the record image was last drawn (screen)
};
struct InsightAction {
  bool refresh = false;
  std::optional<std::uint32_t> select;  ///< a hot node clicked
};
/// `region`: what the rays of state.region touched (null when none is selected).
InsightAction insight_panel(InsightPanelState& state, const ViewInsight* insight, const RegionTouch* region, bool busy,
                            const std::string& error, std::uint32_t selected, const PanelLayout& layout);

// ---- Binned-SAH explainer -------------------------------------------------------------------
struct ExplainerState {
  int buckets = 32;   ///< the build's default (BvhOptions::buckets)
  int axis = -1;      ///< -1: the chosen axis
  bool open = false;  ///< the window was expanded last frame (the explanation is computed only then)
};
/// Returns true when the bucket count changed (re-explain).
bool explainer_panel(ExplainerState& state, const SplitExplanation* e, std::uint32_t node, const std::string& note,
                     const PanelLayout& layout);

/// A Tree row's text: id, prims (leaves), depth, SAH share and, where counted, visits.
std::string tree_row_label(const StructureNode& n, std::uint32_t id, std::optional<std::uint64_t> visits);

// ---- Tree view ------------------------------------------------------------------------------
/// Collapsible tree of `nodes` (count, depth, SAH share, visits when known,
/// with a swatch of the colour `map` gives the node's box by visits); the
/// path to `selected` is opened (and scrolled to when `scroll_to_selected`
/// is set; it is cleared once done). Returns a node the user clicked.
/// `ramp_max`: the visit count at the top of the swatches' ramp; with
/// `ramp_of_boxes` it is the 3D boxes' (SceneView::boxes_visit_max), so a
/// row's swatch is its box's colour (hotter rows, above the boxes drawn, take
/// the top colour), else the tree's largest count (the root's).
std::optional<std::uint32_t> tree_panel(const StructureNodes* nodes, const std::vector<std::uint64_t>* visits,
                                        std::uint32_t selected, bool& scroll_to_selected, const PanelLayout& layout,
                                        ColorMap map, std::uint64_t ramp_max, bool ramp_of_boxes);

// ---- Scenarios ------------------------------------------------------------------------------
struct ScenarioPanelState {
  int current = -1;    ///< index into scenarios(), -1: none chosen
  float value = 0.0f;  ///< the slider
};
struct ScenarioAction {
  bool run = false;                 ///< measure `current` at `value`
  std::optional<std::string> open;  ///< open this scene in the main view
};
ScenarioAction scenarios_panel(ScenarioPanelState& state, const ScenarioFigures* figures, bool busy,
                               const std::string& error, const PanelLayout& layout);

}  // namespace accelviz::panels
