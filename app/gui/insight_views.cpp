#include "app/gui/insight_views.h"

#include <imgui.h>

#include <stdexcept>

#include "core/accel/bvh/bvh.h"
#include "core/util/json_text.h"
#include "ui/app/settings.h"

namespace accelviz {

namespace {

std::uint32_t selected_node(const AppState& app) {
  const int n = app.config().view.box_node;
  return n > 0 ? static_cast<std::uint32_t>(n) : 0u;
}

/// A (pinned) against B (the current choice) on the current scene and camera,
/// at the panel's width and the view's aspect. Needs a pin and a current build.
ABRequest ab_request(const AppState& app, const panels::ABPanelState& ab) {
  ABRequest r;
  r.scene = app.current()->scene;
  r.a = *ab.pinned;
  r.b = app.config().structure;
  r.camera = app.camera();
  r.width = ab.width;
  r.height = app.view_width() > 0 ? std::max(16, ab.width * app.view_height() / app.view_width()) : ab.height;
  return r;
}

void select_node(AppState& app, std::uint32_t id) {
  ViewSettings& v = app.config().view;
  v.show_boxes = true;
  v.box_mode = BoxMode::subtree;
  v.box_node = static_cast<int>(id);
}

nlohmann::json figures_json(const ScenarioFigures& f) {
  nlohmann::json rows = nlohmann::json::array();
  for (const ScenarioRow& r : f.rows)
    rows.push_back({{"structure", r.structure},
                    {"triangles", r.triangles},
                    {"build_ms", r.build_ms},
                    {"sah", r.sah},
                    {"nodes_per_ray", r.nodes_per_ray},
                    {"prims_per_ray", r.prims_per_ray},
                    {"cost_per_ray", r.cost_per_ray},
                    {"leaf_volume_ratio", r.leaf_volume_ratio},
                    {"max_depth", r.max_depth}});
  return {{"id", f.id}, {"value", f.value}, {"scene", f.scene}, {"rows", rows}, {"summary", f.summary}};
}

}  // namespace

bool InsightViews::busy() {
  return ab_job_.busy() || insight_job_.busy() || scenario_job_.busy() || ab_dump_job_.busy();
}

std::shared_ptr<const ViewInsight> InsightViews::shown_insight(const AppState& app) {
  const auto& insight = insight_job_.result();
  return insight && app.current() && insight->built == app.current() ? insight : nullptr;
}

std::shared_ptr<const RegionTouch> InsightViews::region(const std::shared_ptr<const ViewInsight>& insight) {
  if (!insight || !insight_state_.region || insight_state_.region->empty()) {
    region_.reset();
    region_for_ = nullptr;
    return nullptr;
  }
  const PixelRect& r = *insight_state_.region;
  if (!region_ || region_for_ != insight.get() || r.x0 != region_rect_for_.x0 || r.y0 != region_rect_for_.y0 ||
      r.x1 != region_rect_for_.x1 || r.y1 != region_rect_for_.y1) {
    region_ = std::make_shared<const RegionTouch>(region_touch(insight->record, r.x0, r.y0, r.x1, r.y1));
    region_for_ = insight.get();
    region_rect_for_ = r;
  }
  return region_;
}

BoxInsight InsightViews::box_insight(const AppState& app) {
  BoxInsight b;
  b.insight = shown_insight(app);
  b.color_by_visits = insight_state_.hot_boxes;
  b.region = region(b.insight);
  return b;
}

void InsightViews::select_view_region(AppState& app, int ax, int ay, int bx, int by) {
  const auto insight = shown_insight(app);
  if (!insight) {  // measured first, then applied (draw())
    pending_view_region_ = PixelRect{ax, ay, bx, by};
    if (!insight_job_.busy() && app.current()) request_insight(app);
    return;
  }
  pending_view_region_.reset();
  const PixelRect r = view_rect_to_record(ax, ay, bx, by, app.view_width(), app.view_height(), insight->record.width,
                                          insight->record.height);
  if (r.empty())
    insight_state_.region.reset();
  else
    insight_state_.region = r;
}

void InsightViews::draw_labels(const AppState& app, const ViewInsight& v, const panels::PanelLayout& layout) {
  // The selected node is labelled as such only while the boxes show its subtree
  // (box_node is 0, the root, whenever nothing was selected).
  const ViewSettings& view = app.config().view;
  const std::vector<NodeLabel> labels = node_labels(
      v.built->nodes, v.visits, v.hot, static_cast<std::size_t>(std::max(0, insight_state_.labels)),
      view.show_boxes && view.box_mode == BoxMode::subtree ? std::optional<std::uint32_t>(selected_node(app))
                                                           : std::nullopt);
  if (labels.empty() || app.view_width() <= 0 || app.view_height() <= 0) return;
  // Behind every window, over the 3D view; framebuffer pixels to ImGui's window units.
  ImDrawList* dl = ImGui::GetBackgroundDrawList();
  const float sx = layout.width / static_cast<float>(app.view_width());
  const float sy = layout.height / static_cast<float>(app.view_height());
  const Camera cam = app.camera();
  for (const NodeLabel& l : labels) {
    const auto p = project_to_pixel(cam, l.anchor, app.view_width(), app.view_height());
    if (!p) continue;
    const ImVec2 at(p->x * sx, p->y * sy);
    const ImVec2 size = ImGui::CalcTextSize(l.text.c_str());
    const ImVec2 lo(at.x - 2.0f, at.y - size.y - 2.0f), hi(at.x + size.x + 2.0f, at.y + 2.5f);
    // A label under a panel would show faintly through its translucent background.
    if (panels::covered_by_window(lo.x, lo.y, hi.x, hi.y)) continue;
    dl->AddRectFilled(lo, ImVec2(hi.x, at.y), l.selected ? IM_COL32(150, 60, 20, 220) : IM_COL32(20, 20, 20, 200),
                      3.0f);
    dl->AddText(ImVec2(at.x, at.y - size.y - 1.0f), IM_COL32(255, 255, 255, 255), l.text.c_str());
    dl->AddCircleFilled(at, 2.5f, IM_COL32(255, 255, 255, 255));
  }
}

void InsightViews::request_insight(AppState& app) {
  ViewInsightRequest r;
  r.built = app.current();
  r.camera = app.camera();
  if (app.view_width() > 0 && app.view_height() > 0)
    r.height = std::max(16, r.width * app.view_height() / app.view_width());
  insight_job_.request([r](const std::atomic<bool>& cancel) { return run_view_insight(r, cancel); });
}

const SplitExplanation* InsightViews::explanation(const AppState& app, std::string& note) {
  const BuiltStructure* built = app.current().get();
  const Bvh* bvh = built ? dynamic_cast<const Bvh*>(built->accel.get()) : nullptr;
  if (!bvh || bvh->nodes().empty()) {
    note = "The explainer needs a BVH (Structure: bvh).";
    explanation_.reset();
    explained_for_ = nullptr;
    return nullptr;
  }
  const std::uint32_t node =
      std::min<std::uint32_t>(selected_node(app), static_cast<std::uint32_t>(bvh->nodes().size() - 1));
  if (built != explained_for_ || node != explained_node_ || explainer_.buckets != explained_buckets_) {
    BvhOptions o = bvh->options();
    o.buckets = explainer_.buckets;
    try {
      explanation_ = explain_bvh_node(*bvh, node, o);
      explanation_note_ =
          "Tree built with " + std::string(to_string(o.splitter)) +
          (bvh->options().splitter == BvhSplitter::binned_sah ? " B=" + std::to_string(bvh->options().buckets)
                                                              : std::string()) +
          "; explaining node " + std::to_string(node) +
          " (select one in the Tree or hot-node list) "
          "with B=" +
          std::to_string(explainer_.buckets) + ".";
    } catch (const std::exception& e) {
      explanation_.reset();
      explanation_note_ = e.what();
    }
    explained_for_ = built;
    explained_node_ = node;
    explained_buckets_ = explainer_.buckets;
  }
  note = explanation_note_;
  return explanation_ ? &*explanation_ : nullptr;
}

void InsightViews::select(AppState& app, std::uint32_t id) {
  const ViewSettings& v = app.config().view;
  if (!selection_of_) {
    mode_before_selection_ = v.box_mode;
    boxes_before_selection_ = v.show_boxes;
  }
  select_node(app, id);
  selection_of_ = app.current().get();
  selected_id_ = id;
  // Set in this build even when the id is the one already there.
  box_node_seen_ = -1;
  track_box_node(app);
}

void InsightViews::track_box_node(const AppState& app) {
  const int id = app.config().view.box_node;
  const std::shared_ptr<const BuiltStructure>& rest = app.rest();
  // An id from the settings or the command line belongs to the first build shown.
  if (id == box_node_seen_ || !rest) return;
  box_node_seen_ = id;
  box_node_set_in_ = rest;
  box_node_set_in_name_ = describe_structure(rest->choice);
}

std::string InsightViews::box_node_note(const AppState& app) const {
  const ViewSettings& v = app.config().view;
  const BuiltStructure* shown = app.current().get();
  if (v.box_mode != BoxMode::subtree || !shown) return "";
  // describe() walks the subtree (the root's is the whole tree): once per build and id, not per frame.
  const bool blas = shown->nodes.kind() == "tlas" && v.box_level == BoxLevel::blas;
  if (described_.built.lock() != app.current() || described_.id != v.box_node || described_.blas != blas) {
    described_ = {app.current(), v.box_node, blas,
                  blas ? "BLAS node " + std::to_string(v.box_node) + " of each instance shown"
                       : shown->nodes.describe(static_cast<std::uint32_t>(v.box_node))};
  }
  std::string note = described_.text;
  // (An expired build is an earlier one too.)
  if (box_node_seen_ == v.box_node && box_node_set_in_.lock() != app.rest())
    note += "; the id was set in an earlier build (" + box_node_set_in_name_ + "): node ids are per build";
  return note;
}

void InsightViews::drop_stale_selection(AppState& app) {
  if (!selection_of_ || app.current().get() == selection_of_) return;
  ViewSettings& v = app.config().view;
  // Only while the view still shows that selection (not after the user chose another).
  if (v.box_mode == BoxMode::subtree && v.box_node == static_cast<int>(selected_id_)) {
    v.box_mode = mode_before_selection_;
    v.show_boxes = boxes_before_selection_;
  }
  selection_of_ = nullptr;
}

std::uint64_t InsightViews::tree_swatch_max(const AppState& app, std::optional<std::uint64_t> box_ramp_max) {
  if (box_ramp_max) return *box_ramp_max;
  const auto shown = shown_insight(app);
  if (!shown) return 0;
  if (shown != swatch_of_) {
    swatch_of_ = shown;
    swatch_max_ = 0;
    for (const std::uint64_t v : shown->visits) swatch_max_ = std::max(swatch_max_, v);
  }
  return swatch_max_;
}

void InsightViews::request_ab_compare(const AppState& app) {
  if (!ab_.pinned || !app.current()) return;
  ABRequest r = ab_request(app, ab_);
  r.metric = ab_.metric == 1 ? HeatMetric::prims : ab_.metric == 2 ? HeatMetric::cost : HeatMetric::nodes;
  ab_job_.request([r](const std::atomic<bool>& cancel) { return run_ab(r, cancel); });
}

nlohmann::json InsightViews::ab_window_json() {
  const auto res = ab_job_.result();
  nlohmann::json j = {{"shown", res != nullptr}, {"busy", ab_job_.busy()}};
  if (res) {
    j["a"] = describe_choice(res->a);
    j["b"] = describe_choice(res->b);
    j["metric"] = std::string(metric_name(res->image_a.metric));
    j["total_a"] = res->figures.total_a;
    j["total_b"] = res->figures.total_b;
  }
  return j;
}

void InsightViews::draw(AppState& app, const panels::PanelLayout& layout, std::optional<std::uint64_t> box_ramp_max) {
  // A/B.
  const auto ab_result = ab_job_.result();
  const panels::ABAction aa =
      panels::ab_panel(ab_, ab_result.get(), ab_job_.busy(), ab_job_.error(), app.config().structure, layout);
  if (aa.pin) {
    ab_.pinned = app.config().structure;
    app.set_message("pinned " + describe_choice(*ab_.pinned) + " as A");
  }
  if (aa.compare) request_ab_compare(app);

  // A click in the 3D view: the leaf its hit lies in becomes the selection
  // (its path opens in the tree, which scrolls to it). The ray is cast again
  // when another structure is shown, so a click's selection follows it, but
  // only while the view still shows that selection: boxes chosen meanwhile
  // (a box mode set while the build ran) are the user's, not overridden.
  if (app.inspection_version() != inspection_seen_) {
    inspection_seen_ = app.inspection_version();
    const auto& insp = app.inspection();
    const ViewSettings& v = app.config().view;
    const bool still_shown = selection_of_ != nullptr && v.show_boxes && v.box_mode == BoxMode::subtree &&
                             v.box_node == static_cast<int>(selected_id_);
    if (insight_state_.click_selects_leaf && insp && app.current() && (!app.inspection_recast() || still_shown))
      if (const auto leaf = hit_leaf(insp->trace, insp->hit, app.current()->nodes)) {
        select(app, *leaf);
        insight_state_.region.reset();
        scroll_tree_ = true;
      }
  }
  drop_stale_selection(app);
  track_box_node(app);

  // Predicted vs measured, hot nodes.
  const auto insight = shown_insight(app);
  const ViewInsight* shown = insight.get();
  if (pending_view_region_ && shown) {
    const PixelRect p = *pending_view_region_;
    select_view_region(app, p.x0, p.y0, p.x1, p.y1);
  }
  const auto touched = region(insight);
  const panels::InsightAction ia = panels::insight_panel(insight_state_, shown, touched.get(), insight_job_.busy(),
                                                         insight_job_.error(), selected_node(app), layout);
  if (ia.refresh && app.current()) request_insight(app);
  if (ia.select) {
    select(app, *ia.select);
    insight_state_.region.reset();
  }
  if (shown) draw_labels(app, *shown, layout);

  // Explainer: the explanation bins the selected node's triangles (all of them at the root), so
  // only while its window is expanded (a collapsed one cost every build that work on this thread).
  std::string note;
  const SplitExplanation* e = explainer_.open ? explanation(app, note) : nullptr;
  panels::explainer_panel(explainer_, e, explained_node_, note, layout);

  // Tree.
  if (const auto pick =
          panels::tree_panel(app.current() ? &app.current()->nodes : nullptr, shown ? &shown->visits : nullptr,
                             selected_node(app), scroll_tree_, layout, app.config().view.colormap,
                             tree_swatch_max(app, box_ramp_max), box_ramp_max.has_value())) {
    select(app, *pick);
    insight_state_.region.reset();
  }

  // Scenarios.
  const panels::ScenarioAction sa =
      panels::scenarios_panel(scenario_, scenario_job_.figures() ? &*scenario_job_.figures() : nullptr,
                              scenario_job_.busy(), scenario_job_.error(), layout);
  if (sa.run && scenario_.current >= 0)
    scenario_job_.request(scenarios()[static_cast<std::size_t>(scenario_.current)], scenario_.value, {});
  if (sa.open) app.open_scene(*sa.open);
}

nlohmann::json InsightViews::insight_json(const AppState& app) {
  const auto insight = insight_job_.result();
  nlohmann::json j;
  if (!insight) return {{"error", insight_job_.error()}};
  const ViewInsight& v = *insight;
  j["rays"] = v.record.pixel_count();
  j["width"] = v.record.width;
  j["height"] = v.record.height;
  j["is_bvh"] = v.is_bvh;
  if (v.is_bvh)
    j["cost"] = {{"sah", v.cost.sah},
                 {"epo", std::isfinite(v.cost.epo) ? nlohmann::json(v.cost.epo) : nlohmann::json()},
                 {"root_rays", v.cost.root_rays},
                 {"nodes_per_ray", v.cost.nodes_per_ray},
                 {"inner_per_ray", v.cost.inner_per_ray},
                 {"prims_per_ray", v.cost.prims_per_ray},
                 {"cost_per_ray", v.cost.cost_per_ray},
                 {"ratio", v.cost.ratio}};
  nlohmann::json modes = nlohmann::json::object();
  for (const ModeTotals& m : v.modes)
    modes[std::string(mode_name(m.mode))] = {
        {"nodes_per_ray", m.per_ray(m.nodes_visited)},           {"missed_per_ray", m.per_ray(m.nodes_missed)},
        {"culled_per_ray", m.per_ray(m.nodes_culled)},           {"prims_per_ray", m.per_ray(m.prim_tests)},
        {"leaves_skipped_per_ray", m.per_ray(m.leaves_skipped)}, {"hits", m.hits}};
  j["modes"] = modes;
  nlohmann::json hot = nlohmann::json::array();
  for (const HotNode& h : v.hot) hot.push_back({{"node", h.node}, {"visits", h.visits}});
  j["hot"] = hot;
  const std::uint32_t sel = selected_node(app);
  j["selected"] = sel;
  if (v.built) {
    const StructureNode* n = v.built->nodes.node(sel);
    j["selected_is_leaf"] = n && n->leaf;
    j["selected_path"] = path_to(v.built->nodes, sel);
  }
  if (const auto touched = region(insight)) {
    const PixelRect& r = *insight_state_.region;
    j["region"] = {{"x0", r.x0},
                   {"y0", r.y0},
                   {"x1", r.x1},
                   {"y1", r.y1},
                   {"rays", touched->rays},
                   {"nodes", touched->nodes.size()},
                   {"prims", touched->prims.size()},
                   {"hit_prims", touched->hit_prims.size()}};
  } else {
    j["region"] = nullptr;
  }
  std::string note;
  if (const SplitExplanation* e = explanation(app, note)) {
    nlohmann::json axes = nlohmann::json::array();
    for (const AxisExplanation& ax : e->axes) {
      nlohmann::json counts = nlohmann::json::array(), costs = nlohmann::json::array();
      for (const BucketInfo& b : ax.buckets) counts.push_back(b.count);
      for (const double c : ax.cost) costs.push_back(std::isfinite(c) ? nlohmann::json(c) : nlohmann::json());
      axes.push_back({{"usable", ax.usable}, {"counts", counts}, {"cost", costs}});
    }
    j["explainer"] = {{"node", explained_node_},
                      {"buckets", e->buckets},
                      {"prims", e->prims},
                      {"decision", to_string(e->decision)},
                      {"chosen_axis", e->chosen_axis},
                      {"chosen_plane", e->chosen_plane},
                      {"leaf_cost", e->leaf_cost},
                      {"split_cost", std::isfinite(e->split_cost) ? nlohmann::json(e->split_cost) : nlohmann::json()},
                      {"axes", axes}};
  }
  return j;
}

ScriptHost::Status InsightViews::execute(AppState& app, const ScriptCommand& c) {
  using K = ScriptCommand::Kind;
  switch (c.kind) {
    case K::scenario: {
      const auto& all = scenarios();
      for (std::size_t i = 0; i < all.size(); ++i)
        if (all[i].id == c.arg) {
          scenario_.current = static_cast<int>(i);
          scenario_.value = std::stof(c.value);
          scenario_job_.request(all[i], scenario_.value, {});
          panels::request_window("Scenarios", true);  // where the run shows
          return ScriptHost::Status::done;
        }
      throw std::runtime_error("unknown '" + c.arg + "'");
    }
    case K::dump_scenario: {
      if (scenario_job_.busy()) return ScriptHost::Status::again;
      if (!scenario_job_.error().empty()) throw std::runtime_error("scenario: " + scenario_job_.error());
      if (!scenario_job_.figures()) throw std::runtime_error("no scenario run yet (use scenario first)");
      if (const std::string err = write_new_file(c.arg, json_text(figures_json(*scenario_job_.figures()), 2) + "\n");
          !err.empty())
        throw std::runtime_error(err);
      return ScriptHost::Status::done;
    }
    case K::dump_insight: {
      if (!script_insight_requested_) {
        if (!app.settled() || !app.current()) return ScriptHost::Status::again;
        request_insight(app);
        script_insight_requested_ = true;
        return ScriptHost::Status::again;
      }
      if (insight_job_.busy()) return ScriptHost::Status::again;
      script_insight_requested_ = false;
      if (!insight_job_.error().empty()) throw std::runtime_error("insight: " + insight_job_.error());
      if (const std::string err = write_new_file(c.arg, json_text(insight_json(app), 2) + "\n"); !err.empty())
        throw std::runtime_error(err);
      return ScriptHost::Status::done;
    }
    case K::select_region: {
      // Needs the view measured: measure first when it is not (or is stale).
      if (!shown_insight(app)) {
        if (!app.settled() || !app.current()) return ScriptHost::Status::again;
        if (!insight_job_.busy() && !script_insight_requested_) {
          request_insight(app);
          script_insight_requested_ = true;
        }
        if (insight_job_.busy()) return ScriptHost::Status::again;
        script_insight_requested_ = false;
        if (!insight_job_.error().empty()) throw std::runtime_error("insight: " + insight_job_.error());
        if (!shown_insight(app)) return ScriptHost::Status::again;
      }
      // A measurement asked for above may have finished between two frames: the
      // request is answered either way (a stale flag made the next dump-insight
      // write the old figures without measuring).
      script_insight_requested_ = false;
      select_view_region(app, c.x, c.y, c.x2, c.y2);
      if (!insight_state_.region) throw std::runtime_error("select-region: the rectangle lies outside the view");
      return ScriptHost::Status::done;
    }
    case K::pin_a:
      ab_.pinned = app.config().structure;
      app.set_message("pinned " + describe_choice(*ab_.pinned) + " as A");
      panels::request_window("A/B compare", true);  // where A and B show
      return ScriptHost::Status::done;
    case K::dump_ab: {
      if (!ab_.pinned) throw std::runtime_error("dump-ab: nothing pinned as A (use pin-a first)");
      if (!script_ab_requested_) {
        if (!app.settled() || !app.current()) return ScriptHost::Status::again;
        const ABRequest r = ab_request(app, ab_);
        ab_dump_job_.request([r](const std::atomic<bool>& cancel) {
          // Both metrics the lecture compares, each over the same view.
          nlohmann::json out = {
              {"a", describe_choice(r.a)}, {"b", describe_choice(r.b)}, {"width", r.width}, {"height", r.height}};
          for (const HeatMetric m : {HeatMetric::nodes, HeatMetric::prims}) {
            ABRequest rm = r;
            rm.metric = m;
            const ABResult res = run_ab(rm, cancel);
            const ABFigures& f = res.figures;
            // A side that counts nothing per ray (embree): no count compares (null), as render --compare.
            const auto counted = [&](const nlohmann::json& v) {
              return res.uncounted.empty() ? v : nlohmann::json(nullptr);
            };
            out[std::string(metric_name(m))] = {{"total_a", counted(f.total_a)},
                                                {"total_b", counted(f.total_b)},
                                                {"mean_a", counted(f.mean_a)},
                                                {"mean_b", counted(f.mean_b)},
                                                {"b_cheaper", counted(f.b_cheaper)},
                                                {"b_dearer", counted(f.b_dearer)},
                                                {"pixels", f.pixels}};
            out["per_ray_counters"] = res.uncounted.empty();
            out["build_ms_a"] = res.build_ms_a;
            out["build_ms_b"] = res.build_ms_b;
            out["sah_a"] = res.sah_a;
            out["sah_b"] = res.sah_b;
            out["trace_ms_a"] = res.trace_ms_a;
            out["trace_ms_b"] = res.trace_ms_b;
            out["hits_a"] = res.hits_a;
            out["hits_b"] = res.hits_b;
            out["hits_changed"] = res.hits_changed;
          }
          return out;
        });
        script_ab_requested_ = true;
        return ScriptHost::Status::again;
      }
      if (ab_dump_job_.busy()) return ScriptHost::Status::again;
      script_ab_requested_ = false;
      if (!ab_dump_job_.error().empty()) throw std::runtime_error("A/B: " + ab_dump_job_.error());
      if (!ab_dump_job_.result()) throw std::runtime_error("A/B: no result");
      if (const std::string err = write_new_file(c.arg, ab_dump_job_.result()->dump(2) + "\n"); !err.empty())
        throw std::runtime_error(err);
      // The window shows the comparison too (it stayed empty: no script command presses Compare).
      request_ab_compare(app);
      return ScriptHost::Status::done;
    }
    default:
      return ScriptHost::Status::done;
  }
}

}  // namespace accelviz
