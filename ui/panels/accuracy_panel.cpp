// "Cost of accuracy": the sweep of `accelviz sweep` on the current scene,
// run by SweepWorker (ui/app/sweep_worker.h), drawn live with ImGui draw
// lists: build time vs trace time with the Pareto front, each figure against
// the swept parameter, total time for a ray budget, and the calibrated SAH
// constants. Clicking a point (or a bar) asks to apply that setting.
#include <imgui.h>
#include <imgui_stdlib.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "core/analysis/label_placement.h"
#include "ui/panels/panels.h"

namespace accelviz::panels {
namespace {

constexpr ImU32 kAxis = IM_COL32(170, 170, 170, 255);
constexpr ImU32 kGrid = IM_COL32(80, 80, 80, 120);
constexpr ImU32 kPoint = IM_COL32(90, 160, 255, 255);
constexpr ImU32 kFront = IM_COL32(235, 70, 60, 255);
constexpr ImU32 kBest = IM_COL32(80, 220, 110, 255);
constexpr ImU32 kText = IM_COL32(220, 220, 220, 255);

ImU32 series_color(std::size_t i) {
  static const ImU32 c[] = {IM_COL32(90, 160, 255, 255),  IM_COL32(255, 170, 60, 255), IM_COL32(120, 220, 120, 255),
                            IM_COL32(230, 100, 200, 255), IM_COL32(200, 200, 90, 255), IM_COL32(100, 220, 220, 255)};
  return c[i % (sizeof c / sizeof c[0])];
}

std::string short_number(double v) {
  char buf[32];
  const double a = std::fabs(v);
  if (a != 0 && (a >= 1e5 || a < 1e-2))
    std::snprintf(buf, sizeof buf, "%.2g", v);
  else
    std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

// A chart area: an invisible button of `size` (so clicks land here, not on
// the window), axes with min/max ticks, and data → screen mapping.
struct Plot {
  ImVec2 p0, p1;  // plot rectangle (inside the margins)
  double x0 = 0, x1 = 1, y0 = 0, y1 = 1;
  bool clicked = false, hovered = false;
  ImVec2 map(double x, double y) const {
    const double fx = x1 > x0 ? (x - x0) / (x1 - x0) : 0.5, fy = y1 > y0 ? (y - y0) / (y1 - y0) : 0.5;
    return ImVec2(p0.x + static_cast<float>(fx) * (p1.x - p0.x), p1.y - static_cast<float>(fy) * (p1.y - p0.y));
  }
};

void pad_range(double& lo, double& hi, bool from_zero) {
  if (!std::isfinite(lo) || !std::isfinite(hi)) lo = 0, hi = 1;
  if (from_zero && lo > 0) lo = 0;
  if (hi <= lo) hi = lo + (lo == 0 ? 1 : std::fabs(lo) * 0.1);
  const double pad = 0.06 * (hi - lo);
  hi += pad;
  if (!from_zero) lo -= pad;
}

Plot begin_plot(const char* id, float height, double x0, double x1, double y0, double y1, const char* xlabel,
                const char* ylabel, bool x_ticks = true) {
  Plot p;
  const float w = std::max(200.0f, ImGui::GetContentRegionAvail().x);
  const ImVec2 size(w, height);
  const ImVec2 origin = ImGui::GetCursorScreenPos();
  ImGui::InvisibleButton(id, size);
  p.clicked = ImGui::IsItemClicked(ImGuiMouseButton_Left);
  p.hovered = ImGui::IsItemHovered();
  const float lh = ImGui::GetTextLineHeight();
  p.p0 = ImVec2(origin.x + 52.0f, origin.y + lh * 0.5f);
  p.p1 = ImVec2(origin.x + size.x - 8.0f, origin.y + size.y - 2.2f * lh);
  p.x0 = x0, p.x1 = x1, p.y0 = y0, p.y1 = y1;
  ImDrawList* dl = ImGui::GetWindowDrawList();
  dl->AddRect(p.p0, p.p1, kAxis);
  for (int k = 1; k < 4; ++k) {
    const float y = p.p0.y + (p.p1.y - p.p0.y) * k / 4.0f;
    dl->AddLine(ImVec2(p.p0.x, y), ImVec2(p.p1.x, y), kGrid);
  }
  for (int k = 0; k <= 2; ++k) {
    const double v = y0 + (y1 - y0) * k / 2.0;
    const std::string t = short_number(v);
    const ImVec2 at = p.map(x0, v);
    dl->AddText(ImVec2(origin.x + 2.0f, at.y - lh * 0.5f), kText, t.c_str());
    if (x_ticks) {
      const double xv = x0 + (x1 - x0) * k / 2.0;
      const std::string xt = short_number(xv);
      const ImVec2 ax = p.map(xv, y0);
      const float tw = ImGui::CalcTextSize(xt.c_str()).x;
      dl->AddText(ImVec2(std::clamp(ax.x - tw * 0.5f, p.p0.x, p.p1.x - tw), p.p1.y + 1.0f), kText, xt.c_str());
    }
  }
  const float xw = ImGui::CalcTextSize(xlabel).x;
  dl->AddText(ImVec2(0.5f * (p.p0.x + p.p1.x) - 0.5f * xw, p.p1.y + lh + 1.0f), kText, xlabel);
  dl->AddText(ImVec2(p.p0.x + 4.0f, p.p0.y + 2.0f), kText, ylabel);
  return p;
}

// Index of the point nearest the mouse within `radius` pixels, or -1.
int nearest(const std::vector<ImVec2>& screen, float radius) {
  const ImVec2 m = ImGui::GetIO().MousePos;
  int best = -1;
  float bd = radius * radius;
  for (std::size_t i = 0; i < screen.size(); ++i) {
    const float dx = screen[i].x - m.x, dy = screen[i].y - m.y, d = dx * dx + dy * dy;
    if (d <= bd) bd = d, best = static_cast<int>(i);
  }
  return best;
}

void result_tooltip(const SweepResult& r, double budget) {
  ImGui::BeginTooltip();
  ImGui::Text("%s (%s)", setting_label(r.setting).c_str(), r.triangle_test.c_str());
  ImGui::Text("build %.3g ms, trace %.3g ms for %.3g rays, total %.3g ms", r.build_ms, r.trace_ms(budget), budget,
              r.total_ms(budget));
  ImGui::Text("SAH %.4g, %.3g rays/s, %.2f nodes/ray, %.2f tests/ray", r.sah_cost, r.rays_per_s, r.nodes_per_ray,
              r.prims_per_ray);
  if (r.edges.probes)
    ImGui::Text("edge probes %llu: %llu misses, %llu hit both", static_cast<unsigned long long>(r.edges.probes),
                static_cast<unsigned long long>(r.edges.misses), static_cast<unsigned long long>(r.edges.double_hits));
  ImGui::TextDisabled("click: apply this setting to the Structure panel");
  ImGui::EndTooltip();
}

// Build time vs trace time for the budget; returns the clicked result index or -1.
int pareto_chart(const std::vector<SweepResult>& res, double budget, std::size_t best) {
  const std::vector<ParetoPoint> pts = sweep_points(res, budget);
  const std::vector<std::size_t> front = pareto_front(pts);
  double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
  for (const ParetoPoint& p : pts)
    x0 = std::min(x0, p.x), x1 = std::max(x1, p.x), y0 = std::min(y0, p.y), y1 = std::max(y1, p.y);
  pad_range(x0, x1, true);
  pad_range(y0, y1, true);
  char ylabel[64];
  std::snprintf(ylabel, sizeof ylabel, "trace ms for %.3g rays", budget);
  const Plot plot = begin_plot("##pareto", 220.0f, x0, x1, y0, y1, "build ms (median)", ylabel);
  ImDrawList* dl = ImGui::GetWindowDrawList();
  std::vector<ImVec2> screen;
  for (const ParetoPoint& p : pts) screen.push_back(plot.map(p.x, p.y));
  for (std::size_t k = 1; k < front.size(); ++k) dl->AddLine(screen[front[k - 1]], screen[front[k]], kFront, 2.0f);
  // Labels: the best setting's first, then the front's, then (up to ten settings) the others', each
  // where it covers no other label or point; the tooltip names the rest.
  const bool label_all = res.size() <= 10;
  std::vector<std::string> names(res.size());
  std::vector<LabelRequest> requests(res.size());
  std::vector<std::size_t> priority;
  if (best < res.size()) priority.push_back(best);
  priority.insert(priority.end(), front.begin(), front.end());
  for (std::size_t i = 0; i < res.size(); ++i) {
    const bool on_front = std::find(front.begin(), front.end(), i) != front.end();
    dl->AddCircleFilled(screen[i], on_front ? 4.5f : 3.5f, on_front ? kFront : kPoint);
    if (i == best) dl->AddCircle(screen[i], 8.0f, kBest, 0, 2.0f);
    requests[i] = {screen[i].x, screen[i].y, 0.0f, 0.0f};
    if (on_front || label_all || i == best) {
      names[i] = setting_label(res[i].setting);
      const ImVec2 size = ImGui::CalcTextSize(names[i].c_str());
      requests[i].w = size.x;
      requests[i].h = size.y;
      if (!on_front && i != best) priority.push_back(i);
    }
  }
  LabelLayout layout;
  layout.marker = 4.5f;
  layout.bounds = {plot.p0.x + 1.0f, plot.p0.y, plot.p1.x, plot.p1.y};
  const std::vector<std::optional<LabelRect>> spots = place_point_labels(requests, layout, priority);
  for (std::size_t i = 0; i < res.size(); ++i)
    if (spots[i]) {
      const LabelRect& b = *spots[i];  // a leader to the label's nearest corner, as the PNG charts draw
      const ImVec2 corner(screen[i].x < b.x0 ? b.x0 : b.x1, screen[i].y < b.y0 ? b.y0 : b.y1);
      dl->AddLine(screen[i], corner, kText, 1.0f);
      dl->AddText(ImVec2(b.x0, b.y0), kText, names[i].c_str());
    }
  int hit = plot.hovered ? nearest(screen, 9.0f) : -1;
  if (hit >= 0) result_tooltip(res[static_cast<std::size_t>(hit)], budget);
  return plot.clicked ? hit : -1;
}

// One figure against the values of one parameter, a line per combination of the others.
int figure_chart(const std::vector<SweepResult>& res, const SweepParam& param, std::size_t param_index,
                 SweepFigure figure, double budget) {
  const std::vector<SweepSeries> series = sweep_series(res, param_index);
  double y0 = std::numeric_limits<double>::infinity(), y1 = -y0;
  for (const SweepResult& r : res) {
    const double v = sweep_figure_value(r, figure, budget);
    y0 = std::min(y0, v), y1 = std::max(y1, v);
  }
  pad_range(y0, y1, true);
  const double x0 = -0.3, x1 = static_cast<double>(param.values.size()) - 0.7;
  const Plot plot =
      begin_plot("##figure", 200.0f, x0, x1, y0, y1, param.name.c_str(), sweep_figure_name(figure), false);
  ImDrawList* dl = ImGui::GetWindowDrawList();
  const float lh = ImGui::GetTextLineHeight();
  for (std::size_t v = 0; v < param.values.size(); ++v) {
    const ImVec2 at = plot.map(static_cast<double>(v), y0);
    const float tw = ImGui::CalcTextSize(param.values[v].c_str()).x;
    dl->AddText(ImVec2(at.x - tw * 0.5f, plot.p1.y + 1.0f), kText, param.values[v].c_str());
  }
  std::vector<ImVec2> screen(res.size(), ImVec2(-1e9f, -1e9f));
  float legend_y = plot.p0.y + lh + 4.0f;
  for (std::size_t s = 0; s < series.size(); ++s) {
    const ImU32 c = series_color(s);
    ImVec2 prev;
    for (std::size_t k = 0; k < series[s].result.size(); ++k) {
      const std::size_t i = series[s].result[k];
      const ImVec2 p = plot.map(series[s].value_index[k], sweep_figure_value(res[i], figure, budget));
      screen[i] = p;
      if (k > 0) dl->AddLine(prev, p, c, 2.0f);
      dl->AddCircleFilled(p, 3.5f, c);
      prev = p;
    }
    if (!series[s].label.empty() && s < 8) {
      dl->AddText(ImVec2(plot.p1.x - ImGui::CalcTextSize(series[s].label.c_str()).x - 4.0f, legend_y), c,
                  series[s].label.c_str());
      legend_y += lh;
    }
  }
  const int hit = plot.hovered ? nearest(screen, 9.0f) : -1;
  if (hit >= 0) result_tooltip(res[static_cast<std::size_t>(hit)], budget);
  return plot.clicked ? hit : -1;
}

// Total = build + trace for the budget, one bar per setting (build part, trace part).
int total_chart(const std::vector<SweepResult>& res, double budget, std::size_t best) {
  const float lh = ImGui::GetTextLineHeightWithSpacing();
  const float w = std::max(200.0f, ImGui::GetContentRegionAvail().x);
  const float h = lh * static_cast<float>(res.size()) + 4.0f;
  const ImVec2 o = ImGui::GetCursorScreenPos();
  ImGui::InvisibleButton("##total", ImVec2(w, h));
  const bool clicked = ImGui::IsItemClicked(ImGuiMouseButton_Left), hovered = ImGui::IsItemHovered();
  double max_total = 0;
  for (const SweepResult& r : res) max_total = std::max(max_total, r.total_ms(budget));
  if (!(max_total > 0)) max_total = 1;
  ImDrawList* dl = ImGui::GetWindowDrawList();
  const float label_w = std::min(0.4f * w, 170.0f), bar_w = w - label_w - 70.0f;
  int hit = -1;
  for (std::size_t i = 0; i < res.size(); ++i) {
    const float y = o.y + lh * static_cast<float>(i);
    const float xb = o.x + label_w;
    const float bw = static_cast<float>(res[i].build_ms / max_total) * bar_w;
    const float tw = static_cast<float>(res[i].trace_ms(budget) / max_total) * bar_w;
    dl->AddText(ImVec2(o.x, y), i == best ? kBest : kText, setting_label(res[i].setting).c_str());
    dl->AddRectFilled(ImVec2(xb, y + 2), ImVec2(xb + bw, y + lh - 2), IM_COL32(90, 160, 255, 255));
    dl->AddRectFilled(ImVec2(xb + bw, y + 2), ImVec2(xb + bw + tw, y + lh - 2), IM_COL32(255, 170, 60, 255));
    const std::string t = short_number(res[i].total_ms(budget)) + " ms";
    dl->AddText(ImVec2(xb + bw + tw + 4, y), i == best ? kBest : kText, t.c_str());
    const ImVec2 m = ImGui::GetIO().MousePos;
    if (hovered && m.y >= y && m.y < y + lh) hit = static_cast<int>(i);
  }
  if (hit >= 0) result_tooltip(res[static_cast<std::size_t>(hit)], budget);
  return clicked ? hit : -1;
}

void calibration_section(const CalibrationReport& c) {
  ImGui::Text("This machine: box test %.2f ns, watertight triangle %.2f ns, fast triangle %.2f ns", c.machine.ns_box,
              c.machine.ns_triangle_watertight, c.machine.ns_triangle_fast);
  ImGui::Text("Measured constants: C_trav = 1, C_isect = %.3f (watertight %.3f, fast %.3f)", c.c_isect,
              c.machine.c_isect_watertight(), c.machine.c_isect_fast());
  if (ImGui::BeginTable("calib", 3, ImGuiTableFlags_Borders | ImGuiTableFlags_SizingStretchProp)) {
    ImGui::TableSetupColumn("BVH");
    ImGui::TableSetupColumn("default (1, 1)");
    char head[48];
    std::snprintf(head, sizeof head, "calibrated (1, %.3g)", c.c_isect);
    ImGui::TableSetupColumn(head);
    ImGui::TableHeadersRow();
    auto line = [&](const char* name, double a, double b, const char* fmt) {
      ImGui::TableNextRow();
      ImGui::TableSetColumnIndex(0);
      ImGui::TextUnformatted(name);
      ImGui::TableSetColumnIndex(1);
      ImGui::Text(fmt, a);
      ImGui::TableSetColumnIndex(2);
      ImGui::Text(fmt, b);
    };
    const CalibratedTree &d = c.with_default, &k = c.with_calibrated;
    line("SAH cost (calibrated constants)", d.sah_calibrated, k.sah_calibrated, "%.4g");
    line("nodes", static_cast<double>(d.nodes), static_cast<double>(k.nodes), "%.0f");
    line("build ms", d.build_ms, k.build_ms, "%.3g");
    line("rays/s (measured)", d.rays_per_s, k.rays_per_s, "%.4g");
    line("nodes per ray", d.nodes_per_ray, k.nodes_per_ray, "%.2f");
    line("triangle tests per ray", d.prims_per_ray, k.prims_per_ray, "%.2f");
    ImGui::EndTable();
  }
}

}  // namespace

AccuracyAction accuracy_panel(AccuracyPanelState& st, const SweepSnapshot* snap, bool busy,
                              const std::string& structure, const PanelLayout& layout) {
  AccuracyAction act;
  const float s = layout.scale;
  if (!begin_stacked_panel("Cost of accuracy", layout, 4, 560, 640, st.collapsed_at_start)) return act;
  if (st.params_for != structure) {
    st.params = default_sweep_params_text(structure);
    st.params_for = structure;
  }
  ImGui::Text("Sweep %s on the current scene and view", structure.c_str());
  ImGui::SetNextItemWidth(-80.0f * s);
  ImGui::InputText("Params", &st.params);
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip(
        "NAME=V1,V2,... separated by spaces, as `accelviz sweep --param` (e.g. buckets=4,16,exact leaf=1,4 "
        "triangle=watertight,fast)");
  ImGui::SetNextItemWidth(90.0f * s);
  ImGui::InputInt("Rays W", &st.width, 0);
  ImGui::SameLine();
  ImGui::SetNextItemWidth(90.0f * s);
  ImGui::InputInt("H", &st.height, 0);
  ImGui::SameLine();
  ImGui::SetNextItemWidth(70.0f * s);
  ImGui::InputInt("Repeat", &st.repeat, 0);
  st.width = std::clamp(st.width, 8, 4096);
  st.height = std::clamp(st.height, 8, 4096);
  st.repeat = std::clamp(st.repeat, 1, 15);
  ImGui::Checkbox("Calibrate C_trav/C_isect (BVH default vs calibrated)", &st.calibrate);
  if (ImGui::Button(busy ? "Restart sweep" : "Run sweep")) act.run = true;
  ImGui::SameLine();
  ImGui::BeginDisabled(!busy);
  if (ImGui::Button("Cancel")) act.cancel = true;
  ImGui::EndDisabled();
  if (!st.error.empty()) ImGui::TextColored(ImVec4(1.0f, 0.4f, 0.4f, 1.0f), "%s", st.error.c_str());

  if (!snap) {
    ImGui::TextDisabled("No sweep yet.");
    ImGui::End();
    return act;
  }
  const char* state = snap->state == SweepSnapshot::State::running     ? "running"
                      : snap->state == SweepSnapshot::State::done      ? "done"
                      : snap->state == SweepSnapshot::State::cancelled ? "cancelled"
                                                                       : "failed";
  char overlay[160];
  std::snprintf(overlay, sizeof overlay, "%s: %zu/%zu settings%s%s", state, snap->results.size(), snap->settings.size(),
                snap->stage.empty() ? "" : ", ", snap->stage.c_str());
  ImGui::ProgressBar(static_cast<float>(snap->fraction()), ImVec2(-1, 0), overlay);
  if (snap->state == SweepSnapshot::State::failed)
    ImGui::TextColored(ImVec4(1.0f, 0.4f, 0.4f, 1.0f), "%s", snap->error.c_str());
  ImGui::TextDisabled("%zu triangles, %zu primary rays%s", snap->triangles, snap->rays,
                      snap->probes ? (", " + std::to_string(snap->probes) + " shared-edge probes").c_str() : "");

  const std::vector<SweepResult>& res = snap->results;
  int clicked = -1;
  if (!res.empty()) {
    ImGui::SetNextItemWidth(140.0f * s);
    ImGui::InputDouble("Ray budget N", &st.ray_budget, 0, 0, "%.3g");
    if (!(st.ray_budget > 0) || !std::isfinite(st.ray_budget)) st.ray_budget = 1e6;
    const std::size_t best = best_for_budget(res, st.ray_budget);
    // On its own line, wrapped: a long setting label ran off the window beside the budget field.
    ImGui::PushTextWrapPos(0.0f);
    ImGui::TextColored(ImVec4(0.3f, 0.86f, 0.43f, 1.0f), "best for N: %s (%.3g ms)",
                       setting_label(res[best].setting).c_str(), res[best].total_ms(st.ray_budget));
    ImGui::PopTextWrapPos();
    // The fastest may leak through shared edges: name the fastest that does not.
    if (res[best].edges.probes > 0 && res[best].edges.misses > 0) {
      char clean_text[160] = "";
      if (const auto clean = best_without_leaks(res, st.ray_budget))
        std::snprintf(clean_text, sizeof clean_text, "; without leaks: %s (%.3g ms)",
                      setting_label(res[*clean].setting).c_str(), res[*clean].total_ms(st.ray_budget));
      ImGui::PushTextWrapPos(0.0f);
      ImGui::TextColored(ImVec4(1.0f, 0.78f, 0.35f, 1.0f), "it leaks through %llu of %llu shared-edge probes%s",
                         static_cast<unsigned long long>(res[best].edges.misses),
                         static_cast<unsigned long long>(res[best].edges.probes), clean_text);
      ImGui::PopTextWrapPos();
    }

    if (ImGui::CollapsingHeader(snap->probes ? "Build vs trace time (front in red, leaks counted)"
                                             : "Build vs trace time (Pareto front in red)",
                                ImGuiTreeNodeFlags_DefaultOpen)) {
      const int c = pareto_chart(res, st.ray_budget, best);
      if (c >= 0) clicked = c;
    }
    if (ImGui::CollapsingHeader("Total time = build + N x trace", ImGuiTreeNodeFlags_DefaultOpen)) {
      ImGui::TextDisabled("blue: build, orange: trace for N rays; green: least total");
      const int c = total_chart(res, st.ray_budget, best);
      if (c >= 0) clicked = c;
    }
    if (!snap->params.empty() && ImGui::CollapsingHeader("Figure vs parameter", ImGuiTreeNodeFlags_DefaultOpen)) {
      st.param = std::clamp(st.param, 0, static_cast<int>(snap->params.size()) - 1);
      std::vector<const char*> pnames;
      for (const SweepParam& p : snap->params) pnames.push_back(p.name.c_str());
      ImGui::SetNextItemWidth(120.0f * s);
      ImGui::Combo("Parameter", &st.param, pnames.data(), static_cast<int>(pnames.size()));
      ImGui::SameLine();
      std::vector<const char*> fnames;
      for (int f = 0; f < kSweepFigureCount; ++f) fnames.push_back(sweep_figure_name(static_cast<SweepFigure>(f)));
      ImGui::SetNextItemWidth(160.0f * s);
      ImGui::Combo("Figure", &st.figure, fnames.data(), kSweepFigureCount);
      const int c =
          figure_chart(res, snap->params[static_cast<std::size_t>(st.param)], static_cast<std::size_t>(st.param),
                       static_cast<SweepFigure>(st.figure), st.ray_budget);
      if (c >= 0) clicked = c;
    }
    if (ImGui::CollapsingHeader("Table")) {
      if (ImGui::BeginTable("sweep", 8, ImGuiTableFlags_Borders | ImGuiTableFlags_SizingStretchProp)) {
        for (const char* h :
             {"setting", "build ms", "SAH", "rays/s", "nodes/ray", "tests/ray", "edge misses", "edge hit both"})
          ImGui::TableSetupColumn(h);
        ImGui::TableHeadersRow();
        for (std::size_t i = 0; i < res.size(); ++i) {
          const SweepResult& r = res[i];
          ImGui::TableNextRow();
          ImGui::TableSetColumnIndex(0);
          if (ImGui::Selectable(setting_label(r.setting).c_str(), false, ImGuiSelectableFlags_SpanAllColumns))
            clicked = static_cast<int>(i);
          ImGui::TableSetColumnIndex(1);
          ImGui::Text("%.3g", r.build_ms);
          ImGui::TableSetColumnIndex(2);
          ImGui::Text("%.4g", r.sah_cost);
          ImGui::TableSetColumnIndex(3);
          ImGui::Text("%.3g", r.rays_per_s);
          ImGui::TableSetColumnIndex(4);
          ImGui::Text("%.2f", r.nodes_per_ray);
          ImGui::TableSetColumnIndex(5);
          ImGui::Text("%.2f", r.prims_per_ray);
          ImGui::TableSetColumnIndex(6);
          if (r.edges.probes)
            ImGui::Text("%llu/%llu", static_cast<unsigned long long>(r.edges.misses),
                        static_cast<unsigned long long>(r.edges.probes));
          ImGui::TableSetColumnIndex(7);
          if (r.edges.probes)
            ImGui::Text("%llu probes, %llu rays", static_cast<unsigned long long>(r.edges.double_hits),
                        static_cast<unsigned long long>(r.ray_double_hits));
        }
        ImGui::EndTable();
      }
    }
  }
  if (snap->calibration && ImGui::CollapsingHeader("Calibrated constants", ImGuiTreeNodeFlags_DefaultOpen))
    calibration_section(*snap->calibration);
  if (clicked >= 0) {
    act.apply = res[static_cast<std::size_t>(clicked)].setting;
    act.apply_structure = snap->structure;
  }
  ImGui::End();
  return act;
}

}  // namespace accelviz::panels
