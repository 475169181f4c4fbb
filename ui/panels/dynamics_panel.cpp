// Effects by scene (a section appended to the Scene window) and "Dynamics":
// the timeline of an animated scene (play/pause, scrub, speed) and the
// per-frame figures of DynamicsWorker (ui/app/dynamics.h) plotted over time.
#include <imgui.h>

#include <algorithm>
#include <string>
#include <vector>

#include "ui/panels/panels.h"

namespace accelviz::panels {
namespace {

void plot(const char* label, const std::vector<float>& v, float lo, float hi, float height) {
  const float last = v.empty() ? 0.0f : v.back();
  const std::string overlay = "last " + std::to_string(last).substr(0, 8);
  ImGui::PlotLines(label, v.data(), static_cast<int>(v.size()), 0, overlay.c_str(), lo, hi, ImVec2(0.0f, height));
}

}  // namespace

std::optional<std::pair<std::string, bool>> scene_effects_section(const SceneEffects* effects) {
  std::optional<std::pair<std::string, bool>> change;
  if (!effects) return change;
  if (!ImGui::Begin("Scene")) {  // appends to the Scene window
    ImGui::End();
    return change;
  }
  ImGui::Separator();
  ImGui::TextUnformatted("Effects (what this scene calls for):");
  for (const Effect& e : effects->list()) {
    ImGui::PushID(e.name.c_str());
    bool forced = e.forced;
    ImGui::BeginDisabled(!e.forceable || (e.on && !e.forced));
    if (ImGui::Checkbox("force", &forced)) change = std::make_pair(e.name, forced);
    ImGui::EndDisabled();
    if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled))
      ImGui::SetTooltip("%s", !e.forceable        ? "cannot be forced"
                              : e.on && !e.forced ? "on already: the scene calls for it"
                                                  : "force this effect on");
    ImGui::SameLine();
    ImGui::TextColored(e.on ? ImVec4(0.4f, 0.9f, 0.4f, 1.0f) : ImVec4(0.6f, 0.6f, 0.6f, 1.0f), "%s %s", e.name.c_str(),
                       e.on ? "on" : "off");
    ImGui::Indent();
    ImGui::TextWrapped("%s", e.reason.c_str());
    ImGui::Unindent();
    ImGui::PopID();
  }
  ImGui::End();
  return change;
}

void dynamics_panel(DynamicsPlayer& player, const DynamicsSnapshot* snap, bool busy, const PanelLayout& layout) {
  const float s = layout.scale;
  if (!begin_panel("Dynamics", layout, 360, 470, middle_width(layout), 300)) return;
  if (ImGui::Button(player.playing ? "Pause" : "Play")) player.playing = !player.playing;
  ImGui::SameLine();
  ImGui::SetNextItemWidth(90.0f * s);
  ImGui::SliderFloat("Speed", &player.speed, 0.05f, 4.0f, "%.2fx");
  ImGui::SameLine();
  ImGui::TextUnformatted(busy ? "stepping..." : "");
  float t = player.time();
  const float t_max = player.duration > 0.0f ? player.duration : 60.0f;
  if (ImGui::SliderFloat("Time (s)", &t, 0.0f, t_max, "%.3f")) player.seek(t);
  if (player.duration <= 0.0f) ImGui::TextDisabled("procedural motion: no keyframes, the slider covers 60 s");

  if (!snap) {
    ImGui::TextUnformatted("(no frame yet)");
    ImGui::End();
    return;
  }
  if (!snap->error.empty()) ImGui::TextColored(ImVec4(1.0f, 0.4f, 0.4f, 1.0f), "%s", snap->error.c_str());
  ImGui::Text("%llu frames stepped, set-up (two-level build) %.1f ms", static_cast<unsigned long long>(snap->frames),
              snap->setup_ms);
  if (!snap->history.empty()) {
    const FrameStats& f = snap->history.back();
    ImGui::Text("last frame: t=%.3f s, %u instances moved, %u refits, %u rebuilds", static_cast<double>(f.time),
                f.moved_instances, f.refits, f.rebuilds);
  }
  std::vector<float> tlas, refit, rebuild, sah_r, sah_b, overlap;
  for (const FrameStats& f : snap->history) {
    tlas.push_back(static_cast<float>(f.tlas_rebuild_ms));
    refit.push_back(static_cast<float>(f.refit_ms));
    rebuild.push_back(static_cast<float>(f.rebuild_ms));
    sah_r.push_back(static_cast<float>(f.sah_refit));
    sah_b.push_back(static_cast<float>(f.sah_rebuilt));
    overlap.push_back(static_cast<float>(f.overlap.area_ratio));
  }
  const float h = 48.0f * s;
  auto top = [](const std::vector<float>& v) {
    return v.empty() ? 1.0f : std::max(1e-3f, *std::max_element(v.begin(), v.end()));
  };
  plot("TLAS rebuild ms", tlas, 0.0f, top(tlas), h);
  plot("BLAS refit ms", refit, 0.0f, top(refit), h);
  plot("BLAS rebuild ms", rebuild, 0.0f, top(rebuild), h);
  // Both SAH series on one scale, so the gap reads as degradation.
  float lo = 0.0f, hi = 1.0f;
  if (!sah_r.empty()) {
    lo = std::min(*std::min_element(sah_r.begin(), sah_r.end()), *std::min_element(sah_b.begin(), sah_b.end()));
    hi = std::max(*std::max_element(sah_r.begin(), sah_r.end()), *std::max_element(sah_b.begin(), sah_b.end()));
    if (hi <= lo) hi = lo + 1.0f;
  }
  plot("SAH refitted", sah_r, lo, hi, h);
  plot("SAH rebuilt", sah_b, lo, hi, h);
  // Instance overlap (core/accel/tlas/tlas_overlap.h): the sum of pairwise
  // intersection areas of the instances' world boxes over the root's area.
  plot("Instance overlap", overlap, 0.0f, top(overlap), h);
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("sum over instance pairs of the area of their boxes' intersection / the TLAS root's area");
  if (!snap->history.empty()) {
    const InstanceOverlap& o = snap->history.back().overlap;
    ImGui::Text("overlap: %.4g (area), %.4g (volume), %llu overlapping pairs of %llu instances", o.area_ratio,
                o.volume_ratio, static_cast<unsigned long long>(o.overlapping_pairs),
                static_cast<unsigned long long>(o.instances));
  }
  if (snap->frame && snap->frame_is_animator_tree)
    ImGui::Text("view: frame t=%.3f s, the animator's own tree (as refitted/rebuilt above; posed in %.1f ms)",
                static_cast<double>(snap->frame_time), snap->frame_build_ms);
  else if (snap->frame)
    ImGui::Text("view: frame t=%.3f s (%s rebuilt over the posed scene in %.1f ms)",
                static_cast<double>(snap->frame_time), snap->frame->choice.name.c_str(), snap->frame_build_ms);
  ImGui::TextDisabled("The 3D view, heatmap and ray inspector show the latest frame stepped.");
  ImGui::End();
}

}  // namespace accelviz::panels
