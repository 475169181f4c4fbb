// "Flatten what-if" (issue 10): for a two-level structure, choose instances
// (ids or ranges, a checkbox list, or the instance under the last 3D click),
// measure the predicted cost of merging them into one BLAS off the UI thread
// (ui/app/flatten_worker.h), and commit it: the main loop then builds the
// merged scene. Thin: it edits FlattenPanelState and returns an action.
#include <imgui.h>

#include <algorithm>
#include <cinttypes>
#include <string>

#include "ui/panels/panels.h"

namespace accelviz::panels {
namespace {

void figures_row(const char* name, double a, double b, const char* fmt) {
  ImGui::TableNextRow();
  ImGui::TableNextColumn();
  ImGui::TextUnformatted(name);
  ImGui::TableNextColumn();
  ImGui::Text(fmt, a);
  ImGui::TableNextColumn();
  ImGui::Text(fmt, b);
  ImGui::TableNextColumn();
  if (a > 0.0)
    ImGui::TextColored(b <= a ? ImVec4(0.4f, 0.9f, 0.4f, 1.0f) : ImVec4(1.0f, 0.5f, 0.4f, 1.0f), "%+.1f%%",
                       100.0 * (b - a) / a);
}

}  // namespace

void set_flatten_selection(FlattenPanelState& state, std::vector<std::uint32_t> ids) {
  state.selected = std::move(ids);
  state.ids = format_instance_ids(state.selected);
  state.error.clear();
}

FlattenAction flatten_panel(FlattenPanelState& state, const Scene* scene, const FlattenResult* result, bool busy,
                            double fraction, std::optional<std::uint32_t> clicked_instance, const PanelLayout& layout) {
  FlattenAction action;
  const float s = layout.scale;
  const bool collapsed = state.collapsed_at_start;
  state.collapsed_at_start = false;
  if (!begin_stacked_panel("Flatten what-if", layout, 7, 440, 420, collapsed)) return action;
  if (!scene) {
    ImGui::TextDisabled("no scene");
    ImGui::End();
    return action;
  }
  const std::size_t count = scene->instances.size();
  ImGui::TextWrapped("Merge instances into one BLAS of their world triangles: predicted cost first, then commit.");

  // Selection: text (ids, ranges, "all"), the clicked instance, a checkbox list.
  char buf[512];
  std::snprintf(buf, sizeof buf, "%s", state.ids.c_str());
  ImGui::SetNextItemWidth(-80 * s);
  if (ImGui::InputText("Instances", buf, sizeof buf)) {
    state.ids = buf;
    try {
      state.selected = parse_instance_ids(state.ids, count);
      state.error.clear();
    } catch (const std::exception& e) {
      state.error = e.what();
    }
  }
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("ids and ranges, e.g. 0,2,5-9, or all");
  ImGui::BeginDisabled(!clicked_instance.has_value());
  const std::string add = clicked_instance ? "Add clicked instance " + std::to_string(*clicked_instance)
                                           : std::string("Add clicked instance (click one in the view)");
  if (ImGui::Button(add.c_str()) && clicked_instance && *clicked_instance < count) {
    std::vector<std::uint32_t> ids = state.selected;
    if (std::find(ids.begin(), ids.end(), *clicked_instance) == ids.end()) ids.push_back(*clicked_instance);
    std::sort(ids.begin(), ids.end());
    set_flatten_selection(state, std::move(ids));
  }
  ImGui::EndDisabled();
  ImGui::SameLine();
  if (ImGui::Button("Clear")) set_flatten_selection(state, {});
  if (!state.error.empty()) ImGui::TextColored(ImVec4(1.0f, 0.4f, 0.4f, 1.0f), "%s", state.error.c_str());

  if (ImGui::BeginChild("instance list", ImVec2(0, 110 * s), true)) {
    ImGuiListClipper clipper;
    clipper.Begin(static_cast<int>(count));
    while (clipper.Step())
      for (int i = clipper.DisplayStart; i < clipper.DisplayEnd; ++i) {
        const Instance& inst = scene->instances[static_cast<std::size_t>(i)];
        const auto id = static_cast<std::uint32_t>(i);
        const auto it = std::lower_bound(state.selected.begin(), state.selected.end(), id);
        bool on = it != state.selected.end() && *it == id;
        const std::string& mesh = inst.mesh < scene->meshes.size() ? scene->meshes[inst.mesh].name : std::string();
        const std::string& node = inst.node < scene->nodes.size() ? scene->nodes[inst.node].name : std::string();
        const std::string label = std::to_string(i) + "  " + (node.empty() ? "(node)" : node) + "  mesh " +
                                  std::to_string(inst.mesh) + (mesh.empty() ? "" : " " + mesh) + "  " +
                                  std::to_string(inst.triangle_count) + " tris";
        ImGui::PushID(i);
        if (ImGui::Checkbox(label.c_str(), &on)) {
          std::vector<std::uint32_t> ids = state.selected;
          if (on)
            ids.insert(std::lower_bound(ids.begin(), ids.end(), id), id);
          else
            ids.erase(std::lower_bound(ids.begin(), ids.end(), id));
          set_flatten_selection(state, std::move(ids));
        }
        ImGui::PopID();
      }
  }
  ImGui::EndChild();
  ImGui::Text("%zu of %zu instances selected", state.selected.size(), count);

  ImGui::SetNextItemWidth(120 * s);
  int size[2] = {state.width, state.height};
  if (ImGui::InputInt2("rays WxH", size)) {
    state.width = std::clamp(size[0], 8, 1024);
    state.height = std::clamp(size[1], 8, 1024);
  }
  ImGui::BeginDisabled(state.selected.empty() || !state.error.empty());
  if (ImGui::Button("Predict cost")) action.preview = true;
  ImGui::EndDisabled();
  if (busy) {
    ImGui::SameLine();
    if (progress_cancel_row(fraction, nullptr, -1.0f, CancelAt::before)) action.cancel = true;
  }

  // The prediction, if it is of this scene and this selection.
  const bool of_scene = result && result->scene == state.scene_identity;
  if (of_scene && !result->error.empty())
    ImGui::TextColored(ImVec4(1.0f, 0.4f, 0.4f, 1.0f), "%s", result->error.c_str());
  const bool current = of_scene && result->figures && result->instances == state.selected;
  if (of_scene && result->figures) {
    const FlattenWhatIf& w = *result->figures;
    if (!current)
      ImGui::TextDisabled("(for the previous selection: %s)", format_instance_ids(result->instances).c_str());
    ImGui::Text("%" PRIu64 " instances -> one BLAS of %" PRIu64 " triangles, %dx%d rays", w.merged_instances,
                w.merged_triangles, result->width, result->height);
    if (ImGui::BeginTable("flatten figures", 4, ImGuiTableFlags_RowBg | ImGuiTableFlags_BordersInnerV)) {
      ImGui::TableSetupColumn("");
      ImGui::TableSetupColumn("two-level");
      ImGui::TableSetupColumn("flattened");
      ImGui::TableSetupColumn("change");
      ImGui::TableHeadersRow();
      const TwoLevelFigures &a = w.two_level, &b = w.flattened;
      figures_row("nodes / ray", a.mean_nodes, b.mean_nodes, "%.2f");
      figures_row("prim tests / ray", a.mean_prims, b.mean_prims, "%.2f");
      figures_row("instances / ray", a.mean_instances, b.mean_instances, "%.2f");
      figures_row("trace ms", a.trace_ms, b.trace_ms, "%.1f");
      figures_row("memory MiB", static_cast<double>(a.memory_bytes) / 1048576.0,
                  static_cast<double>(b.memory_bytes) / 1048576.0, "%.2f");
      figures_row("SAH cost", a.sah_cost, b.sah_cost, "%.3f");
      figures_row("build ms", a.build_ms, b.build_ms, "%.1f");
      figures_row("instances", static_cast<double>(a.instances), static_cast<double>(b.instances), "%.0f");
      figures_row("BLASes", static_cast<double>(a.blas), static_cast<double>(b.blas), "%.0f");
      ImGui::EndTable();
    }
  }
  ImGui::BeginDisabled(!current || busy);
  if (ImGui::Button("Commit: rebuild with these instances merged")) action.commit = true;
  ImGui::EndDisabled();
  if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled))
    ImGui::SetTooltip("%s", current ? "replaces the scene by the merged one and builds it"
                                    : "predict the cost of this selection first");
  ImGui::End();
  return action;
}

}  // namespace accelviz::panels
