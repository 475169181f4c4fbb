// The Scenarios window: the lecture's cases (ui/app/scenarios.h) with a live
// slider each, the caption of what to look at, and the measured figures per
// structure (growth: nodes per ray against N, plotted).
#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>

#include "ui/panels/insight_panels.h"

namespace accelviz::panels {

ScenarioAction scenarios_panel(ScenarioPanelState& st, const ScenarioFigures* fig, bool busy, const std::string& error,
                               const PanelLayout& layout) {
  ScenarioAction act;
  const float s = layout.scale;
  if (!begin_stacked_panel("Scenarios", layout, 6, 560.0f, 420.0f)) return act;
  const auto& all = scenarios();
  for (int i = 0; i < static_cast<int>(all.size()); ++i) {
    if (i > 0) ImGui::SameLine();
    if (ImGui::RadioButton(all[i].title.c_str(), st.current == i)) {
      st.current = i;
      st.value = all[i].initial;
      act.run = true;
    }
    if (i == 2) ImGui::NewLine();  // two rows of choices
  }
  if (st.current < 0 || st.current >= static_cast<int>(all.size())) {
    ImGui::TextWrapped(
        "Pick a case: each builds its structures over a built-in scene, traces the default view and "
        "shows the measured cost per ray.");
    ImGui::End();
    return act;
  }
  const Scenario& sc = all[st.current];
  ImGui::Separator();
  ImGui::TextWrapped("%s", sc.caption.c_str());
  const ImGuiSliderFlags flags = ImGuiSliderFlags_AlwaysClamp | (sc.log_slider ? ImGuiSliderFlags_Logarithmic : 0);
  ImGui::SliderFloat(sc.slider.c_str(), &st.value, sc.min, sc.max, "%.4g", flags);
  if (ImGui::IsItemDeactivatedAfterEdit()) act.run = true;  // measure on release: each run builds several structures
  ImGui::SameLine();
  if (ImGui::SmallButton("Open in view")) act.open = scenario_scene(sc, st.value);
  if (busy) ImGui::TextDisabled("measuring ...");
  if (!error.empty()) ImGui::TextColored(ImVec4(1.0f, 0.4f, 0.4f, 1.0f), "%s", error.c_str());
  if (fig && fig->id == sc.id) {
    ImGui::Text("%s  (value %.4g)", fig->scene.c_str(), static_cast<double>(fig->value));
    if (ImGui::BeginTable("fig", 8, ImGuiTableFlags_RowBg | ImGuiTableFlags_Borders)) {
      for (const char* h : {"structure", "tris", "build ms", "SAH", "nodes/ray", "prims/ray", "cost/ray", "leaf vol"})
        ImGui::TableSetupColumn(h);
      ImGui::TableHeadersRow();
      for (const ScenarioRow& r : fig->rows) {
        ImGui::TableNextRow();
        ImGui::TableSetColumnIndex(0);
        ImGui::TextUnformatted(r.structure.c_str());
        ImGui::TableSetColumnIndex(1);
        ImGui::Text("%llu", static_cast<unsigned long long>(r.triangles));
        const double vals[] = {r.build_ms,      r.sah,          r.nodes_per_ray,
                               r.prims_per_ray, r.cost_per_ray, r.leaf_volume_ratio};
        for (int k = 0; k < 6; ++k) {
          ImGui::TableSetColumnIndex(k + 2);
          ImGui::Text("%.3g", vals[k]);
        }
      }
      ImGui::EndTable();
    }
    ImGui::TextWrapped("%s", fig->summary.c_str());
    if (sc.id == "growth" && !fig->rows.empty()) {
      // nodes per ray against log N, one line per structure.
      std::map<std::string, std::vector<std::pair<double, double>>> series;
      double x0 = 1e300, x1 = -1e300, y1 = 0.0;
      for (const ScenarioRow& r : fig->rows) {
        const double x = std::log10(static_cast<double>(std::max<std::uint64_t>(r.triangles, 1)));
        series[r.structure].push_back({x, r.nodes_per_ray});
        x0 = std::min(x0, x);
        x1 = std::max(x1, x);
        y1 = std::max(y1, r.nodes_per_ray);
      }
      if (x1 <= x0) x1 = x0 + 1.0;
      if (y1 <= 0.0) y1 = 1.0;
      const float w = ImGui::GetContentRegionAvail().x, h = 120.0f * s;
      ImDrawList* dl = ImGui::GetWindowDrawList();
      const ImVec2 at = ImGui::GetCursorScreenPos();
      dl->AddRect(at, ImVec2(at.x + w, at.y + h), IM_COL32(170, 170, 170, 255));
      const ImU32 colors[] = {IM_COL32(255, 170, 60, 255), IM_COL32(90, 160, 255, 255), IM_COL32(120, 220, 120, 255)};
      int k = 0;
      for (const auto& [name, pts] : series) {
        const ImU32 c = colors[k++ % 3];
        for (std::size_t i = 0; i < pts.size(); ++i) {
          const ImVec2 p(at.x + static_cast<float>((pts[i].first - x0) / (x1 - x0)) * w,
                         at.y + h - static_cast<float>(pts[i].second / y1) * h);
          dl->AddCircleFilled(p, 3.0f, c);
          if (i > 0)
            dl->AddLine(ImVec2(at.x + static_cast<float>((pts[i - 1].first - x0) / (x1 - x0)) * w,
                               at.y + h - static_cast<float>(pts[i - 1].second / y1) * h),
                        p, c, 2.0f);
        }
        dl->AddText(ImVec2(at.x + 4.0f, at.y + 4.0f + 14.0f * (k - 1)), c, name.c_str());
      }
      ImGui::Dummy(ImVec2(w, h));
      ImGui::TextDisabled("nodes entered per ray (y, 0..%.3g) against log10 N (x, %.2f..%.2f)", y1, x0, x1);
    }
  }
  ImGui::End();
  return act;
}

}  // namespace accelviz::panels
