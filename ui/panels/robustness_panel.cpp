// "Robustness": the robustness lab (core/analysis/robustness_lab.h) on the
// current scene, run by RobustnessWorker (ui/app/robustness_worker.h): the
// fast and robust variants side by side (misses, double hits, wrong hits
// against the double-precision reference, and the time of each), per ray
// family, and a per-ray map of the chosen variant (one cell per ray, in
// generation order, coloured by its status).
#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "ui/panels/panels.h"

namespace accelviz::panels {
namespace {

constexpr ImU32 kOk = IM_COL32(70, 70, 70, 255);
constexpr ImU32 kMiss = IM_COL32(235, 60, 50, 255);
constexpr ImU32 kDouble = IM_COL32(240, 200, 60, 255);
constexpr ImU32 kWrong = IM_COL32(220, 80, 220, 255);
constexpr ImU32 kNotTraced = IM_COL32(50, 100, 170, 255);

ImU32 status_color(std::uint8_t s) {
  return s == 1 ? kMiss : s == 2 ? kDouble : s == 3 ? kWrong : s == 4 ? kNotTraced : kOk;
}

void legend_chip(ImU32 c, const char* label) {
  const ImVec2 p = ImGui::GetCursorScreenPos();
  const float h = ImGui::GetTextLineHeight();
  ImGui::GetWindowDrawList()->AddRectFilled(p, ImVec2(p.x + h, p.y + h), c);
  ImGui::Dummy(ImVec2(h, h));
  ImGui::SameLine();
  ImGui::TextUnformatted(label);
  ImGui::SameLine();
}

}  // namespace

RobustnessAction robustness_panel(RobustnessPanelState& st, const RobustnessSnapshot* snap, bool busy,
                                  const std::string& structure, const PanelLayout& layout) {
  RobustnessAction act;
  const float s = layout.scale;
  if (!begin_stacked_panel("Robustness", layout, 5, 620, 560, st.collapsed_at_start)) return act;
  ImGui::TextWrapped(
      "Adversarial rays (through vertices, shared edges, axis-aligned with +0/-0, grazing) traced with "
      "Moller-Trumbore vs watertight triangle tests and plain vs padded slab tests, against the "
      "double-precision reference.");
  ImGui::SetNextItemWidth(120.0f * s);
  ImGui::InputInt("Rays", &st.rays, 1000, 10000);
  st.rays = std::clamp(st.rays, 4, 1 << 22);
  ImGui::SameLine();
  // The box stays unticked and disabled where the lab cannot time the
  // structure's own traversal (the choice is kept for the others).
  const bool unavailable = !lab_times_own_traversal(structure);
  bool with_structure = st.with_structure && !unavailable;
  ImGui::BeginDisabled(unavailable);
  if (ImGui::Checkbox(("Also " + structure + "'s own traversal").c_str(), &with_structure))
    st.with_structure = with_structure;
  ImGui::EndDisabled();
  if (unavailable && ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled))
    ImGui::SetTooltip("not for %s: the lab's variants are triangle tests and slab tests", structure.c_str());
  if (busy) {
    if (ImGui::Button("Cancel")) act.cancel = true;
    ImGui::SameLine();
    ImGui::TextUnformatted("running...");
  } else if (ImGui::Button("Run")) {
    act.run = true;
  }

  if (snap) {
    if (snap->state == RobustnessSnapshot::State::failed)
      ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "%s", snap->error.c_str());
    else if (snap->state == RobustnessSnapshot::State::cancelled)
      ImGui::TextUnformatted("cancelled");
  }
  if (snap && snap->result) {
    const LabResult& r = *snap->result;
    ImGui::Text("%s: %zu triangles, %zu rays (vertex %llu, edge %llu, axis %llu, grazing %llu), reference %.0f ms",
                snap->scene.c_str(), r.triangles, r.rays, static_cast<unsigned long long>(r.rays_by_family[0]),
                static_cast<unsigned long long>(r.rays_by_family[1]),
                static_cast<unsigned long long>(r.rays_by_family[2]),
                static_cast<unsigned long long>(r.rays_by_family[3]), r.reference_ms);
    if (ImGui::BeginTable("variants", 6, ImGuiTableFlags_Borders | ImGuiTableFlags_RowBg)) {
      for (const char* h : {"variant", "misses", "double hits", "wrong", "ms", "Mrays/s"}) ImGui::TableSetupColumn(h);
      ImGui::TableHeadersRow();
      for (std::size_t i = 0; i < r.variants.size(); ++i) {
        const LabVariant& v = r.variants[i];
        ImGui::TableNextRow();
        ImGui::TableNextColumn();
        if (ImGui::Selectable(v.name.c_str(), st.variant == static_cast<int>(i), ImGuiSelectableFlags_SpanAllColumns))
          st.variant = static_cast<int>(i);
        if (ImGui::IsItemHovered()) {
          std::string tip = "misses / double hits by family:";
          for (int f = 0; f < kLabFamilies; ++f)
            tip += std::string("\n  ") + to_string(static_cast<LabFamily>(f)) + ": " +
                   std::to_string(v.misses_by_family[f]) + " / " + std::to_string(v.double_hits_by_family[f]);
          ImGui::SetTooltip("%s", tip.c_str());
        }
        ImGui::TableNextColumn();
        ImGui::Text("%llu", static_cast<unsigned long long>(v.misses));
        ImGui::TableNextColumn();
        if (v.double_hits_counted)
          ImGui::Text("%llu", static_cast<unsigned long long>(v.double_hits));
        else  // Embree reports one hit per ray
          ImGui::TextDisabled("n/a");
        ImGui::TableNextColumn();
        ImGui::Text("%llu", static_cast<unsigned long long>(v.wrong));
        ImGui::TableNextColumn();
        ImGui::Text("%.1f", v.ms);
        ImGui::TableNextColumn();
        ImGui::Text("%.2f", v.mrays_per_s);
      }
      ImGui::EndTable();
    }
    // A structure that refuses the scene or some rays (Embree's limits): its rows count the rays it takes.
    if (!r.structure_refused.empty() || r.structure_rays_refused > 0) {
      ImGui::PushTextWrapPos(0.0f);
      if (!r.structure_refused.empty())
        ImGui::TextColored(ImVec4(1.0f, 0.78f, 0.35f, 1.0f), "%s: not checked: %s", snap->structure.c_str(),
                           r.structure_refused.c_str());
      else
        ImGui::TextColored(ImVec4(1.0f, 0.78f, 0.35f, 1.0f), "%s: %llu of %zu rays not traced (the first, ray %zu: %s)",
                           snap->structure.c_str(), static_cast<unsigned long long>(r.structure_rays_refused), r.rays,
                           r.structure_first_refused_ray, r.structure_refused_ray_reason.c_str());
      ImGui::PopTextWrapPos();
    }
    if (!r.variants.empty()) {
      st.variant = std::clamp(st.variant, 0, static_cast<int>(r.variants.size()) - 1);
      const LabVariant& v = r.variants[static_cast<std::size_t>(st.variant)];
      ImGui::Text("Per ray: %s (one cell per ray, families interleaved)", v.name.c_str());
      legend_chip(kOk, "ok");
      legend_chip(kMiss, "miss");
      legend_chip(kDouble, "double hit");
      legend_chip(kWrong, "wrong");
      if (v.not_traced > 0) legend_chip(kNotTraced, "not traced");
      ImGui::NewLine();
      const float avail = std::max(ImGui::GetContentRegionAvail().x, 50.0f);
      const std::size_t n = v.per_ray.size();
      const int cols = std::max(1, static_cast<int>(std::ceil(std::sqrt(static_cast<double>(n) * 2.0))));
      const float cell = std::max(1.0f, std::floor(avail / static_cast<float>(cols)));
      const int rows = static_cast<int>((n + static_cast<std::size_t>(cols) - 1) / static_cast<std::size_t>(cols));
      const ImVec2 p0 = ImGui::GetCursorScreenPos();
      ImDrawList* dl = ImGui::GetWindowDrawList();
      for (std::size_t i = 0; i < n; ++i) {
        const float x = p0.x + static_cast<float>(i % static_cast<std::size_t>(cols)) * cell;
        const float y = p0.y + static_cast<float>(i / static_cast<std::size_t>(cols)) * cell;
        dl->AddRectFilled(ImVec2(x, y), ImVec2(x + cell, y + cell), status_color(v.per_ray[i]));
      }
      ImGui::Dummy(ImVec2(cell * static_cast<float>(cols), cell * static_cast<float>(rows)));
    }
  } else if (!busy) {
    ImGui::TextUnformatted("Press Run to trace the current scene.");
  }
  ImGui::End();
  return act;
}

}  // namespace accelviz::panels
