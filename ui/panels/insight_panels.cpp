// Insight panels: A/B comparison, predicted vs measured cost with hot nodes
// and traversal modes, the binned-SAH explainer and the tree view. Images
// and charts are drawn with ImGui draw lists (no GL here).
#include "ui/panels/insight_panels.h"

#include <imgui.h>

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

namespace accelviz::panels {
namespace {

ImU32 to_u32(const glm::u8vec3& c) {
  return IM_COL32(c.x, c.y, c.z, 255);
}

// Draws columns [x0, x1) of a metric image at `cell` pixels per image pixel,
// merging runs of equal colour; `color` maps a value to a colour.
template <typename ColorFn>
void draw_image(ImDrawList* dl, ImVec2 at, const MetricImage& img, float cell, int x0, int x1, ColorFn color) {
  for (int y = 0; y < img.height; ++y) {
    int run_start = x0;
    ImU32 run_color = 0;
    for (int x = x0; x <= x1; ++x) {
      const ImU32 c = x < x1 ? to_u32(color(img.at(x, y))) : 0;
      if (x == x0) {
        run_color = c;
        continue;
      }
      if (c != run_color || x == x1) {
        dl->AddRectFilled(ImVec2(at.x + run_start * cell, at.y + y * cell),
                          ImVec2(at.x + x * cell, at.y + (y + 1) * cell), run_color);
        run_start = x;
        run_color = c;
      }
    }
  }
}

const char* kMetricNames[] = {"nodes", "prims", "cost"};

}  // namespace

// ---- A/B ------------------------------------------------------------------------------

ABAction ab_panel(ABPanelState& st, const ABResult* r, bool busy, const std::string& error,
                  const StructureChoice& current, const PanelLayout& layout) {
  ABAction act;
  if (!begin_stacked_panel("A/B compare", layout, 0, 560.0f, 430.0f)) return act;
  if (ImGui::Button("Pin current as A")) act.pin = true;
  ImGui::SameLine();
  ImGui::BeginDisabled(!st.pinned || busy);
  if (ImGui::Button("Compare with B (current)")) act.compare = true;
  ImGui::EndDisabled();
  ImGui::TextWrapped("A: %s", st.pinned ? describe_choice(*st.pinned).c_str() : "(not pinned)");
  ImGui::TextWrapped("B: %s", describe_choice(current).c_str());
  ImGui::SetNextItemWidth(120.0f * layout.scale);
  ImGui::Combo("metric", &st.metric, kMetricNames, 3);
  ImGui::SameLine();
  ImGui::SetNextItemWidth(160.0f * layout.scale);
  ImGui::Combo("display", &st.display, "side by side\0split\0difference B - A\0");
  if (st.display == 1) ImGui::SliderFloat("split", &st.split, 0.0f, 1.0f, "%.2f");
  if (busy) ImGui::TextDisabled("building and tracing A and B ...");
  if (!error.empty()) ImGui::TextColored(ImVec4(1.0f, 0.4f, 0.4f, 1.0f), "%s", error.c_str());
  if (r && r->image_a.width > 0) {
    const ABFigures& f = r->figures;
    if (r->uncounted.empty()) {
      ImGui::Text("totals  A %.0f   B %.0f   B/A %.3f", f.total_a, f.total_b,
                  f.total_a > 0 ? f.total_b / f.total_a : 0.0);
      ImGui::Text("mean per ray  A %.2f   B %.2f   (%s)", f.mean_a, f.mean_b,
                  std::string(metric_name(r->image_a.metric)).c_str());
      ImGui::Text("pixels  B cheaper %" PRIu64 "   B dearer %" PRIu64 "   locked scale 0..%.3g", f.b_cheaper,
                  f.b_dearer, static_cast<double>(r->locked_max));
    } else {
      ImGui::PushTextWrapPos(0.0f);
      ImGui::TextDisabled("%s counts nothing per ray: its image is 0 and no count compares (the times and hits do)",
                          r->uncounted.c_str());
      ImGui::PopTextWrapPos();
    }
    const auto two = [](double v, bool known) {
      char buf[32] = "n/a";
      if (known) std::snprintf(buf, sizeof buf, "%.2f", v);
      return std::string(buf);
    };
    const auto sah = [&](double v) { return two(v, v > 0.0); };
    ImGui::Text("build ms  A %.1f   B %.1f    SAH  A %s   B %s", r->build_ms_a, r->build_ms_b, sah(r->sah_a).c_str(),
                sah(r->sah_b).c_str());
    // What the choice costs in time and what it changes (the counter-free closest hits, as render --compare).
    ImGui::Text("closest hits ms  A %.2f   B %.2f   B/A %s", r->trace_ms_a, r->trace_ms_b,
                two(r->trace_ms_b / r->trace_ms_a, r->trace_ms_a > 0.0).c_str());
    ImGui::Text("rays hit  A %" PRIu64 "   B %" PRIu64 "   hit changed %" PRIu64 " of %zu", r->hits_a, r->hits_b,
                r->hits_changed, r->image_a.values.size());
    const float avail = ImGui::GetContentRegionAvail().x;
    const int w = r->image_a.width, h = r->image_a.height;
    const float cell =
        std::max(1.0f, std::floor((st.display == 0 ? avail / 2.0f - 4.0f : avail) / static_cast<float>(w)));
    ImDrawList* dl = ImGui::GetWindowDrawList();
    const ImVec2 at = ImGui::GetCursorScreenPos();
    ColorizeOptions co;
    const auto seq = [&](float v) { return heatmap_color(r->image_a.metric, v, r->locked_max, co); };
    if (st.display == 0) {
      draw_image(dl, at, r->image_a, cell, 0, w, seq);
      draw_image(dl, ImVec2(at.x + w * cell + 8.0f, at.y), r->image_b, cell, 0, w, seq);
      ImGui::Dummy(ImVec2(2 * w * cell + 8.0f, h * cell));
      ImGui::Text("A (left), B (right), one colour scale");
    } else if (st.display == 1) {
      const int cut = std::clamp(static_cast<int>(std::lround(st.split * w)), 0, w);
      draw_image(dl, at, r->image_a, cell, 0, cut, seq);
      draw_image(dl, at, r->image_b, cell, cut, w, seq);
      dl->AddLine(ImVec2(at.x + cut * cell, at.y), ImVec2(at.x + cut * cell, at.y + h * cell),
                  IM_COL32(255, 255, 255, 255));
      ImGui::Dummy(ImVec2(w * cell, h * cell));
      ImGui::Text("A left of the line, B right of it");
    } else {
      const float s = r->diff_scale;
      draw_image(dl, at, r->diff, cell, 0, w, [s](float v) { return difference_color(v, s, glm::vec3(0.3f)); });
      ImGui::Dummy(ImVec2(w * cell, h * cell));
      ImGui::Text("B - A: blue B cheaper, red B dearer, scale +-%.3g", static_cast<double>(s));
    }
  }
  ImGui::End();
  return act;
}

// ---- Predicted vs measured ----------------------------------------------------------------

InsightAction insight_panel(InsightPanelState& st, const ViewInsight* v, const RegionTouch* region, bool busy,
                            const std::string& error, std::uint32_t selected, const PanelLayout& layout) {
  InsightAction act;
  if (!begin_stacked_panel("Predicted vs measured", layout, 1, 470.0f, 480.0f)) return act;
  if (ImGui::Button(busy ? "Measuring ..." : "Measure this view")) act.refresh = true;
  if (!error.empty()) ImGui::TextColored(ImVec4(1.0f, 0.4f, 0.4f, 1.0f), "%s", error.c_str());
  if (!v) {
    ImGui::TextWrapped("Traces the view's primary rays (128 x 96) with every visit recorded.");
    ImGui::End();
    return act;
  }
  if (v->is_bvh) {
    const CostComparison& c = v->cost;
    if (ImGui::BeginTable("cost", 2, ImGuiTableFlags_RowBg)) {
      const auto row2 = [](const char* name, const char* fmt, double x) {
        ImGui::TableNextRow();
        ImGui::TableSetColumnIndex(0);
        ImGui::TextUnformatted(name);
        ImGui::TableSetColumnIndex(1);
        ImGui::Text(fmt, x);
      };
      // Per ray that enters the root box (the SAH's condition), not per ray of the view as the
      // modes table below: the same walk read 10.85 here and 4.97 there.
      row2("SAH expected cost / root ray", "%.3f", c.sah);
      row2("EPO", "%.3f", c.epo);
      row2("measured cost / root ray", "%.3f", c.cost_per_ray);
      row2("measured / SAH", "%.3f", c.ratio);
      row2("nodes entered / root ray", "%.3f", c.nodes_per_ray);
      row2("inner nodes / root ray", "%.3f", c.inner_per_ray);
      row2("primitive tests / root ray", "%.3f", c.prims_per_ray);
      row2("rays entering the root", "%.0f", static_cast<double>(c.root_rays));
      ImGui::EndTable();
    }
    ImGui::PushTextWrapPos(0.0f);
    ImGui::TextDisabled(
        "Per root ray: over the rays that enter the root box, the SAH's condition. Measured cost = C_trav x inner "
        "nodes + C_isect x primitive tests, as the SAH counts (the heatmap's cost metric counts every node "
        "entered, leaves too).");
    ImGui::PopTextWrapPos();
  } else {
    ImGui::TextDisabled("SAH prediction: BVH only.");
  }
  ImGui::Separator();
  ImGui::TextUnformatted("Traversal modes (per ray of the view, all of them)");
  if (ImGui::BeginTable("modes", 6, ImGuiTableFlags_RowBg | ImGuiTableFlags_Borders)) {
    for (const char* h : {"mode", "entered", "missed", "culled", "prims", "skipped"}) ImGui::TableSetupColumn(h);
    ImGui::TableHeadersRow();
    for (const ModeTotals& m : v->modes) {
      ImGui::TableNextRow();
      ImGui::TableSetColumnIndex(0);
      ImGui::TextUnformatted(std::string(mode_name(m.mode)).c_str());
      const std::uint64_t vals[] = {m.nodes_visited, m.nodes_missed, m.nodes_culled, m.prim_tests, m.leaves_skipped};
      for (int k = 0; k < 5; ++k) {
        ImGui::TableSetColumnIndex(k + 1);
        ImGui::Text("%.2f", m.per_ray(vals[k]));
      }
    }
    ImGui::EndTable();
  }
  ImGui::Separator();
  ImGui::TextUnformatted("Hot nodes (click to select)");
  if (ImGui::BeginTable("hot", 5, ImGuiTableFlags_RowBg | ImGuiTableFlags_ScrollY,
                        ImVec2(0.0f, 160.0f * layout.scale))) {
    for (const char* h : {"node", "visits", "depth", "p(SA)", "measured"}) ImGui::TableSetupColumn(h);
    ImGui::TableHeadersRow();
    for (const HotNode& hn : v->hot) {
      ImGui::TableNextRow();
      ImGui::TableSetColumnIndex(0);
      char label[32];
      std::snprintf(label, sizeof label, "%u", hn.node);
      if (ImGui::Selectable(label, hn.node == selected, ImGuiSelectableFlags_SpanAllColumns)) act.select = hn.node;
      ImGui::TableSetColumnIndex(1);
      ImGui::Text("%" PRIu64, hn.visits);
      ImGui::TableSetColumnIndex(2);
      const StructureNode* n = v->built ? v->built->nodes.node(hn.node) : nullptr;
      ImGui::Text("%u", n ? n->depth : 0u);
      ImGui::TableSetColumnIndex(3);
      if (hn.node < v->predicted.size()) ImGui::Text("%.3f", v->predicted[hn.node]);
      ImGui::TableSetColumnIndex(4);
      if (hn.node < v->measured.size()) ImGui::Text("%.3f", v->measured[hn.node]);
    }
    ImGui::EndTable();
  }
  ImGui::Checkbox("Colour boxes by visits", &st.hot_boxes);
  ImGui::SameLine();
  ImGui::SetNextItemWidth(90.0f * layout.scale);
  ImGui::SliderInt("labels", &st.labels, 0, 20, "top %d");
  ImGui::Checkbox("3D click selects the hit's leaf", &st.click_selects_leaf);
  // The view's rays: nodes entered per pixel, the selected node's pixels in
  // orange; drag a rectangle to select a region.
  const int rw = v->record.width, rh = v->record.height;
  if (rw > 0 && rh > 0 && v->record.stats.size() == static_cast<std::size_t>(rw) * rh) {
    ImGui::Text("Nodes entered per pixel; orange: rays that entered node %u (%llu rays)", selected,
                static_cast<unsigned long long>(selected < v->visits.size() ? v->visits[selected] : 0));
    ImGui::TextDisabled("Drag on the image to select a region (or Ctrl+drag in the 3D view).");
    const std::vector<std::uint8_t> mask = pixels_visiting(v->record, selected);
    std::uint32_t max_nodes = 1;
    for (const RayStats& r : v->record.stats) max_nodes = std::max(max_nodes, r.nodes_visited);
    const float cell = std::max(1.0f, std::floor(2.0f * layout.scale));
    ImDrawList* dl = ImGui::GetWindowDrawList();
    const ImVec2 at = ImGui::GetCursorScreenPos();
    for (int y = 0; y < rh; ++y)
      for (int x = 0; x < rw; ++x) {
        const std::size_t p = static_cast<std::size_t>(y) * rw + x;
        const glm::vec3 c =
            mask[p] ? glm::vec3(1.0f, 0.75f, 0.25f)
                    : colormap(ColorMap::viridis, static_cast<float>(v->record.stats[p].nodes_visited) / max_nodes);
        dl->AddRectFilled(
            ImVec2(at.x + x * cell, at.y + y * cell), ImVec2(at.x + (x + 1) * cell, at.y + (y + 1) * cell),
            IM_COL32(static_cast<int>(c.x * 255), static_cast<int>(c.y * 255), static_cast<int>(c.z * 255), 255));
      }
    st.image_x = at.x;
    st.image_y = at.y;
    st.image_cell = cell;
    ImGui::InvisibleButton("record", ImVec2(rw * cell, rh * cell));
    const ImVec2 m = ImGui::GetIO().MousePos;
    const int mx = std::clamp(static_cast<int>(std::floor((m.x - at.x) / cell)), 0, rw);
    const int my = std::clamp(static_cast<int>(std::floor((m.y - at.y) / cell)), 0, rh);
    if (ImGui::IsItemActivated()) {
      st.dragging = true;
      st.drag_x = mx;
      st.drag_y = my;
    }
    std::optional<PixelRect> shown = st.region;
    if (st.dragging) {
      const PixelRect r{std::min(st.drag_x, mx), std::min(st.drag_y, my), std::max(st.drag_x, mx) + 1,
                        std::max(st.drag_y, my) + 1};
      shown = PixelRect{r.x0, r.y0, std::min(r.x1, rw), std::min(r.y1, rh)};
      if (!ImGui::IsItemActive()) {
        st.dragging = false;
        st.region = shown;
      }
    }
    if (shown && !shown->empty())
      dl->AddRect(ImVec2(at.x + shown->x0 * cell, at.y + shown->y0 * cell),
                  ImVec2(at.x + shown->x1 * cell, at.y + shown->y1 * cell), IM_COL32(255, 255, 255, 255), 0.0f, 0,
                  2.0f);
  }
  if (st.region) {
    if (region)
      ImGui::TextWrapped(
          "Region x %d..%d, y %d..%d: %llu rays entered %zu distinct nodes, tested %zu distinct primitives, "
          "hit %zu (boxes and primitives highlighted in the 3D view)",
          st.region->x0, st.region->x1 - 1, st.region->y0, st.region->y1 - 1,
          static_cast<unsigned long long>(region->rays), region->nodes.size(), region->prims.size(),
          region->hit_prims.size());
    if (ImGui::SmallButton("Clear region")) st.region.reset();
  }
  ImGui::End();
  return act;
}

// ---- Explainer -------------------------------------------------------------------------------

bool explainer_panel(ExplainerState& st, const SplitExplanation* e, std::uint32_t node, const std::string& note,
                     const PanelLayout& layout) {
  bool changed = false;
  st.open = begin_stacked_panel("SAH explainer", layout, 2, 520.0f, 460.0f);
  if (!st.open) return false;
  changed = ImGui::SliderInt("buckets B", &st.buckets, 2, 64, "%d", ImGuiSliderFlags_AlwaysClamp);
  ImGui::Combo("axis", &st.axis, "x\0y\0z\0");
  ImGui::SameLine();
  if (ImGui::SmallButton("chosen")) st.axis = -1;
  if (!note.empty()) ImGui::TextWrapped("%s", note.c_str());
  if (!e) {
    ImGui::End();
    return changed;
  }
  ImGui::TextWrapped("node %u: %zu primitives, decision: %s", node, e->prims, to_string(e->decision));
  // Wrapped: at the window's default width the line was cut at "(too man".
  ImGui::TextWrapped("leaf cost C_isect*N = %.3f   best split = %.3f%s", e->leaf_cost, e->split_cost,
                     e->leaf_allowed ? "" : "  (too many for a leaf)");
  if (e->decision == SplitDecision::unsplittable)
    ImGui::TextWrapped(
        "All centroids lie in one bucket on every axis: the SAH cannot separate them; the builder "
        "falls back to an object median split.");
  const int axis = st.axis >= 0 ? st.axis : std::max(0, e->chosen_axis);
  const AxisExplanation& ax = e->axes[axis];
  if (!ax.usable) {
    ImGui::Text("axis %c: centroids do not spread (no candidate planes)", "xyz"[axis]);
    ImGui::End();
    return changed;
  }
  const int nb = static_cast<int>(ax.buckets.size());
  std::uint32_t max_count = 1;
  for (const BucketInfo& b : ax.buckets) max_count = std::max(max_count, b.count);
  double cmin = std::numeric_limits<double>::infinity(), cmax = -cmin;
  for (const double c : ax.cost)
    if (std::isfinite(c)) cmin = std::min(cmin, c), cmax = std::max(cmax, c);
  if (!std::isfinite(cmin)) {
    cmin = 0.0;
    cmax = 1.0;
  } else if (!(cmax > cmin)) {
    cmax = cmin + 1.0;
  }
  const float width = ImGui::GetContentRegionAvail().x, bar_h = 100.0f * layout.scale, curve_h = 100.0f * layout.scale;
  ImDrawList* dl = ImGui::GetWindowDrawList();
  const ImVec2 at = ImGui::GetCursorScreenPos();
  const float bw = width / static_cast<float>(nb);
  // Histogram of bucket counts.
  for (int b = 0; b < nb; ++b) {
    const float hgt = bar_h * static_cast<float>(ax.buckets[b].count) / static_cast<float>(max_count);
    dl->AddRectFilled(ImVec2(at.x + b * bw + 1, at.y + bar_h - hgt), ImVec2(at.x + (b + 1) * bw - 1, at.y + bar_h),
                      IM_COL32(90, 160, 255, 255));
  }
  // Cost curve over the B-1 planes, below; the chosen plane in red across both.
  const float cy = at.y + bar_h + 10.0f;
  ImVec2 prev;
  bool have_prev = false;
  for (int p = 0; p + 1 < nb; ++p) {
    if (!std::isfinite(ax.cost[p])) {
      have_prev = false;
      continue;
    }
    const ImVec2 pt(at.x + (p + 1) * bw, cy + curve_h * static_cast<float>(1.0 - (ax.cost[p] - cmin) / (cmax - cmin)));
    if (have_prev) dl->AddLine(prev, pt, IM_COL32(255, 170, 60, 255), 2.0f);
    dl->AddCircleFilled(pt, 2.5f, IM_COL32(255, 170, 60, 255));
    prev = pt;
    have_prev = true;
  }
  if (e->chosen_axis == axis && e->chosen_plane >= 0) {
    const float x = at.x + (e->chosen_plane + 1) * bw;
    dl->AddLine(ImVec2(x, at.y), ImVec2(x, cy + curve_h), IM_COL32(235, 70, 60, 255), 2.0f);
  }
  // The leaf cost as a dashed level when it falls within the curve's range.
  if (e->leaf_cost >= cmin && e->leaf_cost <= cmax) {
    const float y = cy + curve_h * static_cast<float>(1.0 - (e->leaf_cost - cmin) / (cmax - cmin));
    for (float x = at.x; x < at.x + width; x += 8.0f)
      dl->AddLine(ImVec2(x, y), ImVec2(x + 4.0f, y), IM_COL32(120, 220, 120, 255));
  }
  ImGui::Dummy(ImVec2(width, bar_h + 10.0f + curve_h));
  ImGui::TextDisabled(
      "blue: primitives per bucket; orange: SAH cost per plane (%.3g .. %.3g); red: chosen; green: leaf", cmin, cmax);
  if (ImGui::BeginTable("buckets", 5, ImGuiTableFlags_RowBg | ImGuiTableFlags_ScrollY,
                        ImVec2(0.0f, 140.0f * layout.scale))) {
    for (const char* h : {"bucket", "centroids in", "count", "plane after", "cost"}) ImGui::TableSetupColumn(h);
    ImGui::TableHeadersRow();
    for (int b = 0; b < nb; ++b) {
      ImGui::TableNextRow();
      ImGui::TableSetColumnIndex(0);
      ImGui::Text("%d", b);
      ImGui::TableSetColumnIndex(1);
      ImGui::Text("[%.3g, %.3g)", static_cast<double>(ax.buckets[b].lo), static_cast<double>(ax.buckets[b].hi));
      ImGui::TableSetColumnIndex(2);
      ImGui::Text("%u", ax.buckets[b].count);
      if (b + 1 < nb) {
        ImGui::TableSetColumnIndex(3);
        ImGui::Text("%.3g (%u | %zu)", static_cast<double>(ax.plane[b]), ax.left[b], e->prims - ax.left[b]);
        ImGui::TableSetColumnIndex(4);
        const bool chosen = e->chosen_axis == axis && e->chosen_plane == b;
        if (std::isfinite(ax.cost[b]))
          ImGui::Text(chosen ? "%.3f  <" : "%.3f", ax.cost[b]);
        else
          ImGui::TextDisabled("(side empty)");
      }
    }
    ImGui::EndTable();
  }
  ImGui::End();
  return changed;
}

// ---- Tree view -------------------------------------------------------------------------------------

namespace {

bool on_path(const StructureNodes& nodes, std::uint32_t id, std::uint32_t selected) {
  for (const StructureNode* n = nodes.node(selected); n; n = nodes.node(n->parent)) {
    if (selected == id) return true;
    if (n->parent == 0xFFFFFFFFu) break;
    selected = n->parent;
  }
  return selected == id;
}

/// How rows show visits: the boxes' colour ramp (ui/app/hot_nodes.h) up to
/// `max_visits`, as a swatch before the row.
struct RowColors {
  ColorMap map;
  std::uint64_t max_visits;
};

void tree_rows(const StructureNodes& nodes, const std::vector<std::uint64_t>* visits, const RowColors& rc,
               std::uint32_t id, std::uint32_t selected, std::optional<std::uint32_t>& clicked, bool& scroll,
               int budget_depth) {
  const StructureNode* n = nodes.node(id);
  if (!n) return;
  const unsigned long long vis = visits && id < visits->size() ? static_cast<unsigned long long>((*visits)[id]) : 0ull;
  const std::string label = tree_row_label(*n, id, visits ? std::optional<std::uint64_t>(vis) : std::nullopt);
  ImGuiTreeNodeFlags flags = ImGuiTreeNodeFlags_OpenOnArrow | ImGuiTreeNodeFlags_SpanAvailWidth;
  if (n->leaf) flags |= ImGuiTreeNodeFlags_Leaf | ImGuiTreeNodeFlags_NoTreePushOnOpen;
  if (id == selected) flags |= ImGuiTreeNodeFlags_Selected;
  // The root opens on first show: with the root selected (the default, or a click on a pixel that
  // missed) no path forces it open, and the panel showed one collapsed row.
  if (id == 0) flags |= ImGuiTreeNodeFlags_DefaultOpen;
  if (!n->leaf && id != selected && on_path(nodes, id, selected)) ImGui::SetNextItemOpen(true, ImGuiCond_Always);
  ImGui::PushID(static_cast<int>(id));
  if (visits) {
    // The same colour the node's box gets when boxes are coloured by visits.
    const glm::vec3 c = colormap(rc.map, visit_ramp(vis, rc.max_visits));
    ImGui::ColorButton("##visits", ImVec4(c.x, c.y, c.z, 1.0f),
                       ImGuiColorEditFlags_NoTooltip | ImGuiColorEditFlags_NoDragDrop,
                       ImVec2(ImGui::GetTextLineHeight(), ImGui::GetTextLineHeight()));
    ImGui::SameLine();
  }
  const bool open = ImGui::TreeNodeEx("n", flags, "%s", label.c_str());
  if (ImGui::IsItemClicked() && !ImGui::IsItemToggledOpen()) clicked = id;
  if (id == selected && scroll) {
    ImGui::SetScrollHereY(0.5f);
    scroll = false;
  }
  if (open && !n->leaf) {
    if (budget_depth > 0)
      for (const std::uint32_t c : nodes.children(id))
        tree_rows(nodes, visits, rc, c, selected, clicked, scroll, budget_depth - 1);
    ImGui::TreePop();
  }
  ImGui::PopID();
}

}  // namespace

std::string tree_row_label(const StructureNode& n, std::uint32_t id, std::optional<std::uint64_t> visits) {
  char label[160], visits_text[48] = "";
  if (visits)  // none counted: no figure (it printed a bare 0 after the SAH share)
    std::snprintf(visits_text, sizeof visits_text, ", visits %llu", static_cast<unsigned long long>(*visits));
  if (n.leaf)
    std::snprintf(label, sizeof label, "leaf %u  (%u prims, depth %u, SAH %.2f%%%s)", id, n.prims, n.depth,
                  100.0 * n.sah_share, visits_text);
  else
    std::snprintf(label, sizeof label, "node %u  (depth %u, SAH %.2f%%%s)", id, n.depth, 100.0 * n.sah_share,
                  visits_text);
  return label;
}

std::optional<std::uint32_t> tree_panel(const StructureNodes* nodes, const std::vector<std::uint64_t>* visits,
                                        std::uint32_t selected, bool& scroll_to_selected, const PanelLayout& layout,
                                        ColorMap map, std::uint64_t ramp_max, bool ramp_of_boxes) {
  std::optional<std::uint32_t> clicked;
  if (!begin_stacked_panel("Tree", layout, 3, 420.0f, 420.0f)) return clicked;
  if (!nodes || nodes->empty() || nodes->kind() == "grid") {
    ImGui::TextDisabled("The structure shown has no tree.");
  } else {
    ImGui::TextDisabled("%s, %llu nodes; click a row to select its subtree in the 3D view", nodes->kind().c_str(),
                        static_cast<unsigned long long>(nodes->size()));
    const RowColors rc{map, ramp_max};
    if (visits && ramp_of_boxes)
      ImGui::TextDisabled("swatch: the 3D boxes' colours, top colour from %llu visits (the hottest box drawn)",
                          static_cast<unsigned long long>(ramp_max));
    else if (visits)
      ImGui::TextDisabled("swatch: visits on the boxes' colour ramp, top colour %llu visits (the root's)",
                          static_cast<unsigned long long>(ramp_max));
    tree_rows(*nodes, visits, rc, 0, selected, clicked, scroll_to_selected, 128);
  }
  ImGui::End();
  return clicked;
}

}  // namespace accelviz::panels
