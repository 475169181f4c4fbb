#pragma once
// The insight windows of the GUI (A/B compare, predicted vs measured with
// hot nodes and traversal modes, SAH explainer, tree view, scenarios): their
// state, their background jobs, and the script commands that drive them
// (scenario, dump-scenario, dump-insight). gui_main.cpp owns one and calls
// draw() once per frame.
#include <nlohmann/json.hpp>
#include <optional>

#include "app/gui/scene_view.h"
#include "core/analysis/insight/sah_explainer.h"
#include "ui/app/app_state.h"
#include "ui/app/hot_nodes.h"
#include "ui/app/insight_jobs.h"
#include "ui/app/scenarios.h"
#include "ui/app/script.h"
#include "ui/panels/insight_panels.h"

namespace accelviz {

class InsightViews {
 public:
  /// `box_ramp_max`: the visit count at the top of the 3D boxes' colour ramp
  /// when they are drawn by visits, which the Tree's swatches then share.
  void draw(AppState& app, const panels::PanelLayout& layout, std::optional<std::uint64_t> box_ramp_max);
  /// The visit count at the top of the Tree's swatch ramp: `box_ramp_max`
  /// when set, else the shown insight's largest count (the root's); 0 without one.
  std::uint64_t tree_swatch_max(const AppState& app, std::optional<std::uint64_t> box_ramp_max);
  /// scenario, dump-scenario, dump-insight, select-region, pin-a, dump-ab.
  ScriptHost::Status execute(AppState& app, const ScriptCommand& c);
  /// What the 3D view shows of the insight: boxes by visits, a region's nodes and primitives.
  BoxInsight box_insight(const AppState& app);
  /// Selects the record pixels under a rectangle of the 3D view (view pixels, corners in any order).
  void select_view_region(AppState& app, int ax, int ay, int bx, int by);
  /// A job is running (keep frames coming).
  bool busy();
  /// The latest ray inspection's consequences (a click selects the leaf its
  /// hit lies in) are applied: the script's `wait` waits for it too.
  bool caught_up(const AppState& app) { return inspection_seen_ == app.inspection_version() && !ab_job_.busy(); }
  /// The subtree mode's node id in words: what it names in the structure
  /// shown (StructureNodes::describe) and, when it was set (typed, or
  /// selected) while another build was shown, which one: node ids are per
  /// build. "" outside subtree mode.
  std::string box_node_note(const AppState& app) const;
  /// The subtree node id was set again (a script's `set box-node`, which
  /// waits for a build on its way), perhaps to the same number: it belongs
  /// to the build shown.
  void box_node_set_again(const AppState& app) {
    box_node_seen_ = -1;
    track_box_node(app);
  }
  /// What the A/B window shows, for dump-stats: `shown` (a comparison is
  /// there), `busy`, and when shown its sides `a`, `b`, `metric`, `total_a`,
  /// `total_b`.
  nlohmann::json ab_window_json();

 private:
  /// The A/B window's Compare: the pinned A against the structure shown, in
  /// the window's metric, run in the background.
  void request_ab_compare(const AppState& app);
  /// Selects node `id` of the structure shown (the Boxes view's subtree mode),
  /// remembering the box mode it replaces.
  void select(AppState& app, std::uint32_t id);
  /// A node selected in another structure than the one now shown names
  /// nothing there: the box mode before it comes back.
  void drop_stale_selection(AppState& app);
  /// Notes the build shown (at rest) when the subtree node id changes.
  void track_box_node(const AppState& app);
  void request_insight(AppState& app);
  /// The measured insight when it belongs to the structure shown.
  std::shared_ptr<const ViewInsight> shown_insight(const AppState& app);
  /// What the selected region's rays touched (cached per insight and rectangle).
  std::shared_ptr<const RegionTouch> region(const std::shared_ptr<const ViewInsight>& insight);
  void draw_labels(const AppState& app, const ViewInsight& v, const panels::PanelLayout& layout);
  const SplitExplanation* explanation(const AppState& app, std::string& note);
  nlohmann::json insight_json(const AppState& app);

  panels::ABPanelState ab_;
  AsyncJob<ABResult> ab_job_;
  AsyncJob<ViewInsight> insight_job_;
  panels::InsightPanelState insight_state_;
  std::shared_ptr<const RegionTouch> region_;
  const ViewInsight* region_for_ = nullptr;
  PixelRect region_rect_for_;
  std::optional<PixelRect> pending_view_region_;  ///< select-region before a measurement: applied once measured
  std::uint64_t inspection_seen_ = 0;
  /// The structure (build) the selected node belongs to (null: no selection
  /// made here), the node, and the box view it replaced.
  const BuiltStructure* selection_of_ = nullptr;
  std::uint32_t selected_id_ = 0;
  BoxMode mode_before_selection_ = BoxMode::depth;
  bool boxes_before_selection_ = true;
  bool scroll_tree_ = false;
  /// The build (at rest) shown when the subtree node id got its value, its
  /// description, and that value (-1: none seen yet).
  std::weak_ptr<const BuiltStructure> box_node_set_in_;
  std::string box_node_set_in_name_;
  int box_node_seen_ = -1;
  /// box_node_note's description of (build, id, level), kept while they stay.
  struct Described {
    std::weak_ptr<const BuiltStructure> built;  // (a freed build's address may come back)
    int id = -1;
    bool blas = false;
    std::string text;
  };
  mutable Described described_;
  AsyncJob<nlohmann::json> ab_dump_job_;
  bool script_ab_requested_ = false;
  panels::ExplainerState explainer_;
  /// The largest visit count of this insight (tree_swatch_max: once per insight, not per frame).
  std::shared_ptr<const ViewInsight> swatch_of_;
  std::uint64_t swatch_max_ = 0;
  panels::ScenarioPanelState scenario_;
  ScenarioJob scenario_job_;
  bool script_insight_requested_ = false;

  // The explanation shown, for (structure, node, buckets).
  const BuiltStructure* explained_for_ = nullptr;
  std::uint32_t explained_node_ = 0;
  int explained_buckets_ = 0;
  std::optional<SplitExplanation> explanation_;
  std::string explanation_note_;
};

}  // namespace accelviz
