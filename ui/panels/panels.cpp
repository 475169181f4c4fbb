#include "ui/panels/panels.h"

#include <imgui.h>
#include <imgui_internal.h>  // ImGuiWindow::SizeFull: the size a resize asked for this frame
#include <imgui_stdlib.h>

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <map>
#include <string>
#include <thread>

#include "core/accel/factory.h"
#include "core/analysis/heatmap.h"
#include "core/scene/load.h"
#include "core/util/one_line.h"
#include "ui/app/shortcuts.h"
#include "ui/render/overlays.h"

namespace accelviz::panels {
namespace {

/// A note that something is not as it looks (amber; errors are red).
const ImVec4 kWarnColour(1.0f, 0.78f, 0.35f, 1.0f);

// First-use placement, designed for a 1280×800 window: scene, structure and
// screenshot on the left, stats and view on the right but clear of the
// heatmap legend (the renderer draws it along the right edge), the ray
// inspector at the bottom in between, the insight windows stacked collapsed
// at the top in between, all clear of the status line. Vertical positions and
// heights follow the window's height; x < 0 counts from the right edge.
// ImGui's saved layout replaces this afterwards; follow_display() keeps it in
// the window when the window is resized.
constexpr float kReferenceHeight = 800.0f;  ///< the window height the layout was designed for
constexpr float kMiddleX = 356.0f;          ///< the left edge of the strip between the columns
constexpr float kMiddleWidth = 470.0f;      ///< its width in a 1280-wide window, less a margin

constexpr float kRightColumn = 438.0f;  ///< the right column's left edge, from the window's right edge

float vertical_factor(const PanelLayout& l) {
  return std::clamp(l.height / (kReferenceHeight * l.scale), 0.5f, 4.0f);
}

}  // namespace

float middle_width(const PanelLayout& l) {
  const float room = l.width / l.scale - kMiddleX - kRightColumn - 8.0f;
  return std::clamp(room, 160.0f, kMiddleWidth);
}

namespace {

void place(const PanelLayout& l, float x, float y, float w, float h) {
  const float s = l.scale, f = vertical_factor(l);
  const float px = x >= 0.0f ? x * s : l.width + x * s;
  ImGui::SetNextWindowPos(ImVec2(px, y * s * f), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(w * s, h * s * f), ImGuiCond_FirstUseEver);
}

/// The top of stacked insight window `slot`: title bars one below the other
/// (their spacing does not scale, so bars placed at any window height line up).
float stacked_y(const PanelLayout& l, int slot) {
  return 8.0f * l.scale * vertical_factor(l) + static_cast<float>(slot) * (ImGui::GetFrameHeight() + 4.0f * l.scale);
}

/// Called between Begin and End: when the window (the display) changed size
/// since this panel's last frame, a panel in the right half keeps its
/// distance to the right edge, and every panel's top and height scale with
/// the height, so the columns stay clear of each other and of the status line;
/// a stacked insight window (`slot` >= 0) goes back to its place in the stack.
void follow_display(const PanelLayout& l, int slot) {
  ImGuiStorage* st = ImGui::GetStateStorage();
  const ImGuiID kw = ImGui::GetID("##display_w"), kh = ImGui::GetID("##display_h");
  const ImGuiID kx = ImGui::GetID("##pos_x"), ky = ImGui::GetID("##pos_y");
  const ImGuiID kn = ImGui::GetID("##natural_w"), ks = ImGui::GetID("##set_w");
  const float w0 = st->GetFloat(kw, 0.0f), h0 = st->GetFloat(kh, 0.0f);
  ImGuiWindow* w = ImGui::GetCurrentWindow();
  // The width the panel wants: its first one, or the user's since (not one a resize below set).
  if (w->SizeFull.x != st->GetFloat(ks, -1.0f)) st->SetFloat(kn, w->SizeFull.x);
  if (w0 > 0.0f && h0 > 0.0f && (w0 != l.width || h0 != l.height)) {
    // Where it was in the last frame: ImGui has already pulled a window the
    // smaller display would hide back into it (pos.y = height - 19), which
    // scaled would land on the panel above. SizeFull, not GetWindowSize(): a
    // size set in the frame before (two resizes in a row) shows there already.
    ImVec2 pos(st->GetFloat(kx, w->Pos.x), st->GetFloat(ky, w->Pos.y));
    ImVec2 size = w->SizeFull;
    if (pos.x + size.x * 0.5f > w0 * 0.5f) {
      pos.x += l.width - w0;
    } else {
      // Left of the right column: as wide as it wants where there is room, narrower where there is not
      // (a window made narrower than 1280: the insight windows and the Ray panel covered the column).
      const float room = l.width - (kRightColumn + 8.0f) * l.scale - pos.x;
      const float natural = st->GetFloat(kn, size.x);
      size.x = std::max(std::min(natural, 160.0f * l.scale), std::min(natural, room));
      st->SetFloat(ks, size.x);
    }
    const float f = l.height / h0;
    pos.y = slot >= 0 ? stacked_y(l, slot) : pos.y * f;
    ImGui::SetWindowPos(pos);
    size.y *= f;
    ImGui::SetWindowSize(size);
  }
  st->SetFloat(kw, l.width);
  st->SetFloat(kh, l.height);
  st->SetFloat(kx, w->Pos.x);
  st->SetFloat(ky, w->Pos.y);
}

std::string bytes_text(std::uint64_t b) {
  char buf[64];
  if (b >= (1ull << 30))
    std::snprintf(buf, sizeof buf, "%.2f GiB", static_cast<double>(b) / (1ull << 30));
  else if (b >= (1ull << 20))
    std::snprintf(buf, sizeof buf, "%.2f MiB", static_cast<double>(b) / (1ull << 20));
  else if (b >= 1024)
    std::snprintf(buf, sizeof buf, "%.1f KiB", static_cast<double>(b) / 1024.0);
  else
    std::snprintf(buf, sizeof buf, "%" PRIu64 " B", b);
  return buf;
}

void row(const char* name, const char* fmt, ...) IM_FMTARGS(2);
void row(const char* name, const char* fmt, ...) {
  ImGui::TableNextRow();
  ImGui::TableSetColumnIndex(0);
  ImGui::TextUnformatted(name);
  ImGui::TableSetColumnIndex(1);
  ImGui::PushTextWrapPos(0.0f);  // a long value wraps in its column instead of being cut
  va_list args;
  va_start(args, fmt);
  ImGui::TextV(fmt, args);
  va_end(args);
  ImGui::PopTextWrapPos();
}

// A combo over a fixed list of names; returns true when the index changed.
bool combo(const char* label, int& index, const std::vector<const char*>& names) {
  return ImGui::Combo(label, &index, names.data(), static_cast<int>(names.size()));
}

bool float_positive(const char* label, float& v, float speed, const char* help) {
  float x = v;
  const bool changed = ImGui::DragFloat(label, &x, speed, 1e-3f, 1e4f, "%.3g", ImGuiSliderFlags_AlwaysClamp);
  if (help && ImGui::IsItemHovered()) ImGui::SetTooltip("%s", help);
  if (changed && x > 0.0f && std::isfinite(x) && x != v) {
    v = x;
    return true;
  }
  return false;
}

// ImGui 1.86 has no SeparatorText (1.89): a rule and a label.
void section(const char* label) {
  ImGui::Separator();
  ImGui::TextDisabled("%s", label);
}

// The key to the ray replay's box colours in the 3D view: a ramp from the
// first box entered to the current step's (RayPathStyle's colours).
void visit_fade_key() {
  const RayPathStyle style;
  const auto col = [](const glm::vec4& c) { return ImGui::ColorConvertFloat4ToU32(ImVec4(c.x, c.y, c.z, 1.0f)); };
  ImGui::TextDisabled("boxes entered: first");
  ImGui::SameLine();
  const float w = 90.0f * ImGui::GetFontSize() / 13.0f, h = ImGui::GetTextLineHeight();
  const ImVec2 p = ImGui::GetCursorScreenPos();
  ImGui::GetWindowDrawList()->AddRectFilledMultiColor(p, ImVec2(p.x + w, p.y + h), col(style.first_visit),
                                                      col(style.last_visit), col(style.last_visit),
                                                      col(style.first_visit));
  ImGui::Dummy(ImVec2(w, h));
  ImGui::SameLine();
  ImGui::TextDisabled("this step");
}

bool checkbox(const char* label, bool& v, const char* help = nullptr) {
  const bool changed = ImGui::Checkbox(label, &v);
  if (help && ImGui::IsItemHovered()) ImGui::SetTooltip("%s", help);
  return changed;
}

// Sliders that commit only when released would hide the supersession the
// app is built for; a drag rebuilds at every new value and each newer build
// cancels the older one.
bool slider_int(const char* label, int& v, int lo, int hi, const char* help = nullptr) {
  const bool changed = ImGui::SliderInt(label, &v, lo, hi, "%d", ImGuiSliderFlags_AlwaysClamp);
  if (help && ImGui::IsItemHovered()) ImGui::SetTooltip("%s", help);
  return changed;
}

}  // namespace

// ---- Scene ------------------------------------------------------------------------

SceneAction scene_panel(std::string& path_field, const std::vector<std::string>& recent, const Scene* scene,
                        const std::string& shown_spec, int active_camera, const PanelLayout& layout) {
  SceneAction a;
  if (!begin_panel("Scene", layout, 8, 8, 340, 260)) return a;
  ImGui::TextWrapped("%s", shown_spec.empty() ? "(loading...)" : shown_spec.c_str());
  ImGui::SetNextItemWidth(-70.0f * layout.scale);
  const bool enter = ImGui::InputTextWithHint("##path", ".gltf/.glb/.obj or builtin:NAME?size=N", &path_field,
                                              ImGuiInputTextFlags_EnterReturnsTrue);
  ImGui::SameLine();
  if ((ImGui::Button("Open") || enter) && !path_field.empty()) a.open = path_field;

  if (ImGui::BeginCombo("Built-in", "choose...")) {
    for (const BuiltinSceneInfo& b : builtin_scenes()) {
      if (ImGui::Selectable(b.name.c_str())) {
        path_field = "builtin:" + b.name;
        a.open = path_field;
      }
      if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s\n%s", b.description.c_str(), b.parameters.c_str());
    }
    ImGui::EndCombo();
  }
  if (ImGui::BeginCombo("Recent", recent.empty() ? "(none)" : "choose...")) {
    for (const std::string& r : recent)
      if (ImGui::Selectable(r.c_str())) {
        path_field = r;
        a.open = r;
      }
    ImGui::EndCombo();
  }

  if (scene) {
    ImGui::Separator();
    ImGui::Text("%s triangles", triangle_count_text(*scene).c_str());
    ImGui::Text("%s, %s", count_of(scene->meshes.size(), "mesh").c_str(),
                count_of(scene->instances.size(), "instance").c_str());
    ImGui::Text("%s, %s", count_of(scene->lights.size(), "light").c_str(),
                count_of(scene->cameras.size(), "camera").c_str());
    if (scene->report.dropped_nonfinite || scene->report.degenerate)
      ImGui::Text("%" PRIu64 " dropped (non-finite), %" PRIu64 " degenerate", scene->report.dropped_nonfinite,
                  scene->report.degenerate);
    for (const std::string& w : scene->report.warnings) ImGui::TextWrapped("warning: %s", w.c_str());
    if (!scene->cameras.empty()) {
      ImGui::TextUnformatted("Cameras:");
      for (std::size_t i = 0; i < scene->cameras.size(); ++i) {
        const std::string label = std::to_string(i) + ": " +
                                  (scene->cameras[i].name.empty() ? std::string("camera") : scene->cameras[i].name);
        if (ImGui::RadioButton(label.c_str(), active_camera == static_cast<int>(i))) a.camera = static_cast<int>(i);
      }
    }
    if (ImGui::Button("Reset view (R)")) a.reset_view = true;
  }
  ImGui::End();
  return a;
}

// ---- Structure -------------------------------------------------------------------------

namespace {

/// The BVH's build options (a bvh, and each BLAS and the TLAS of a tlas).
bool bvh_option_widgets(BvhOptions& b) {
  bool changed = false;
  int splitter = static_cast<int>(b.splitter);
  if (combo("Splitter", splitter, {"binned SAH", "exact SAH", "median", "LBVH (Morton)"})) {
    b.splitter = static_cast<BvhSplitter>(splitter);
    changed = true;
  }
  if (b.splitter == BvhSplitter::binned_sah)
    changed |= slider_int("Buckets", b.buckets, 2, 256, "binned SAH bucket count");
  // Not "max leaf size": leaves grow past it up to the cap where the SAH rates them cheaper.
  // "Always-leaf size" was cut to "Always-leaf siz" at the panel's width.
  if (slider_int("Always-leaf", b.max_leaf_size, 1, 255,
                 "a node with at most this many triangles is always a leaf (max_leaf_size, --leaf); larger "
                 "leaves, up to the cap below, where the SAH rates them cheaper than a split")) {
    b.leaf_size_cap = std::max(b.leaf_size_cap, b.max_leaf_size);
    changed = true;
  }
  changed |= slider_int("Leaf size cap", b.leaf_size_cap, b.max_leaf_size, 255,
                        "largest leaf the SAH may keep when cheaper than a split");
  changed |= float_positive("C_trav", b.cost_traversal, 0.01f, "SAH cost of an inner-node visit");
  changed |= float_positive("C_isect", b.cost_intersect, 0.01f, "SAH cost of a triangle test");
  changed |= checkbox("EPO", b.compute_epo, "compute the effective primitive overlap (Aila 2013) after the build");
  return changed;
}

}  // namespace

bool structure_panel(StructureChoice& choice, const BuildProgress& progress, bool& cancel, const PanelLayout& layout) {
  cancel = false;
  bool changed = false;
  if (!begin_panel("Structure", layout, 8, 276, 340, 400)) return false;
  const std::vector<std::string>& names = structure_names();
  if (ImGui::BeginCombo("Type", choice.name.c_str())) {
    for (const std::string& n : names)
      if (ImGui::Selectable(n.c_str(), n == choice.name) && n != choice.name) {
        choice.name = n;
        changed = true;
      }
    ImGui::EndCombo();
  }

  StructureOptions& o = choice.options;
  if (choice.name == "bvh") {
    changed |= bvh_option_widgets(o.bvh);
  } else if (choice.name == "tlas") {
    ImGui::TextDisabled("BVH options, for each BLAS and the TLAS");
    changed |= bvh_option_widgets(o.bvh);
  } else if (choice.name == "kdtree") {
    KdTreeOptions& k = o.kdtree;
    changed |= float_positive("C_trav", k.cost_traversal, 0.01f, nullptr);
    changed |= float_positive("C_isect", k.cost_intersect, 0.01f, nullptr);
    changed |= slider_int("Max depth", k.max_depth, 0, kKdMaxDepth, "0: automatic, 8 + 1.3 log2 N");
    changed |= slider_int("Max leaf size", k.max_leaf_size, 1, 64, nullptr);
    changed |= ImGui::SliderFloat("Empty bonus", &k.empty_bonus, 0.0f, 1.0f, "%.2f", ImGuiSliderFlags_AlwaysClamp);
    changed |= checkbox("Perfect splits", k.perfect_splits, "clip triangles to the node box (Havran 2000)");
    changed |= checkbox("Mailboxing", k.mailboxing, nullptr);
  } else if (choice.name == "grid") {
    GridOptions& g = o.grid;
    bool automatic = g.resolution[0] == 0;
    if (checkbox("Automatic resolution", automatic, "about lambda * N cells, shaped to the bounds")) {
      g.resolution = automatic ? std::array<int, 3>{0, 0, 0} : std::array<int, 3>{16, 16, 16};
      changed = true;
    }
    if (automatic) {
      changed |= float_positive("Lambda", g.lambda, 0.05f, "cells per triangle");
    } else {
      int r[3] = {g.resolution[0], g.resolution[1], g.resolution[2]};
      if (ImGui::InputInt3("Cells x,y,z", r)) {
        for (int a = 0; a < 3; ++a) g.resolution[a] = std::clamp(r[a], 1, 4096);
        changed = true;
      }
    }
    changed |= checkbox("Exact overlap", g.exact_overlap, "reference a triangle only in cells it really overlaps");
    changed |= checkbox("Mailboxing", g.mailboxing, nullptr);
  } else if (choice.name == "octree") {
    OctreeOptions& t = o.octree;
    changed |= slider_int("Max depth", t.max_depth, 0, kOctreeMaxDepth, nullptr);
    changed |= slider_int("Max leaf size", t.max_leaf_size, 1, 64, "cells with more triangles are split");
    changed |= checkbox("Mailboxing", t.mailboxing, nullptr);
    changed |= checkbox("Cost termination", t.cost_termination, "stop where the SAH rates the split no cheaper");
  } else if (choice.name == "voxels") {
    changed |= slider_int("Level", o.voxels.level, 0, kVoxelMaxLevel, "2^level voxels per axis");
  } else if (choice.name == "embree") {
    int q = static_cast<int>(o.embree.quality);
    if (combo("Quality", q, {"low (Morton)", "medium (binned SAH)", "high (spatial splits)"})) {
      o.embree.quality = static_cast<EmbreeQuality>(q);
      changed = true;
    }
    changed |= checkbox("Robust", o.embree.robust, nullptr);
    int isa = static_cast<int>(o.embree.isa);  // EmbreeIsa's order
    if (combo("Kernels", isa,
              {"auto (widest the CPU has)", "SSE2", "SSE4.2", "AVX", "AVX2 (our fast path's)", "AVX-512"})) {
      o.embree.isa = static_cast<EmbreeIsa>(isa);
      changed = true;
    }
  } else {
    ImGui::TextDisabled("no build options");
  }
  if (choice.name != "brute" && choice.name != "brute-bbox") {
    int threads = static_cast<int>(o.threads);
    const int hw = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    if (slider_int("Threads", threads, 0, hw, "build threads; 0 = all hardware threads")) {
      o.threads = static_cast<unsigned>(threads);
      changed = true;
    }
  }

  section("Query");
  int test = choice.query.triangle_test == TriangleTest::watertight ? 0 : 1;
  bool query_changed = ImGui::RadioButton("Watertight", &test, 0);
  ImGui::SameLine();
  query_changed |= ImGui::RadioButton("Fast (Moller-Trumbore)", &test, 1);
  if (query_changed) choice.query.triangle_test = test == 0 ? TriangleTest::watertight : TriangleTest::moller_trumbore;
  query_changed |= checkbox("Ordered traversal", choice.query.ordered, "front-to-back child order (off: fixed order)");
  changed |= query_changed;

  ImGui::Separator();
  ImGui::TextWrapped("Shown: %s", progress.shown.empty() ? "(none yet)" : progress.shown.c_str());
  if (progress.busy &&
      progress_cancel_row(progress.fraction, progress.stage.c_str(), -80.0f * layout.scale, CancelAt::after))
    cancel = true;
  ImGui::End();
  return changed;
}

// ---- Stats ---------------------------------------------------------------------------------

void stats_panel(const BuiltStructure* built, const HeatmapFrame* view, const PanelLayout& layout) {
  if (!begin_panel("Stats", layout, -kRightColumn, 8, 320, 340)) return;
  if (!built) {
    ImGui::TextDisabled("no structure yet");
    ImGui::End();
    return;
  }
  const BuildStats& b = built->accel->build_stats();
  ImGui::Text("%s", built->accel->name().c_str());
  if (ImGui::BeginTable("build", 2, ImGuiTableFlags_RowBg | ImGuiTableFlags_BordersInnerV)) {
    // The names as wide as the longest (the extras' keys are long), the values the rest.
    ImGui::TableSetupColumn("name", ImGuiTableColumnFlags_WidthFixed);
    ImGui::TableSetupColumn("value", ImGuiTableColumnFlags_WidthStretch);
    row("build ms", "%.2f", b.build_ms);
    row("wall ms", "%.2f", built->wall_ms);
    if (built->accel->inspectable()) {
      row("nodes", "%" PRIu64, b.node_count);
      row("leaves", "%" PRIu64, b.leaf_count);
      row("max depth", "%u", b.max_depth);
      row("avg leaf depth", "%.2f", b.avg_leaf_depth);
    } else {
      row("nodes", "n/a: %s keeps its tree to itself", built->accel->name().c_str());
    }
    row("memory", "%s", bytes_text(b.memory_bytes).c_str());
    if (b.sah_cost > 0.0) {
      // Under the structure's own constants (the K-D tree's C_isect is 1.5): compare SAH costs of
      // two structures only under the same ones.
      const std::string c = sah_constants_text(built->accel->name(), built->choice.options);
      row("SAH cost", "%s%s", figure_text(b.sah_cost).c_str(), c.empty() ? "" : ("  (" + c + ")").c_str());
    } else
      row("SAH cost", "n/a");
    if (const auto it = b.extra.find("epo"); it != b.extra.end()) row("EPO", "%.4g", it->second);
    for (const auto& [k, v] : b.extra) {
      if (k == "epo") continue;
      if ((k.starts_with("memory_") || k.ends_with("_bytes")) && v >= 0.0 && v < 1.8e19)
        row(k.c_str(), "%s", bytes_text(static_cast<std::uint64_t>(v)).c_str());
      else if (v == std::floor(v) && std::abs(v) < 1e15)
        row(k.c_str(), "%.0f", v);  // counts: 192320, not 1.9232e+05
      else
        row(k.c_str(), "%.6g", v);
    }
    ImGui::EndTable();
  }
  section("Current view");
  if (!view) {
    ImGui::TextDisabled("tracing...");
  } else {
    const HeatmapSummary& s = view->summary;
    // After a switch the view still shows the structure before until the new one's first level is
    // traced: say whose figures these are (they read as the new structure's under its heading).
    if (view->request.structure && view->request.structure.get() != built)
      ImGui::TextColored(ImVec4(1.0f, 0.78f, 0.35f, 1.0f), "of %s, the structure before: %s",
                         view->request.structure->choice.name.c_str(),
                         built ? "the new one's view is being traced" : "no structure now");
    if (ImGui::BeginTable("view", 2, ImGuiTableFlags_RowBg | ImGuiTableFlags_BordersInnerV)) {
      ImGui::TableSetupColumn("name", ImGuiTableColumnFlags_WidthFixed);
      ImGui::TableSetupColumn("value", ImGuiTableColumnFlags_WidthStretch);
      row("pixels", "%d x %d%s", view->image.width, view->image.height,
          view->complete ? "" : (" (1 in " + std::to_string(view->stride * view->stride) + ")").c_str());
      const bool counted =
          !view->request.structure || !view->request.structure->accel || view->request.structure->accel->inspectable();
      if (!counted) {
        row("nodes / pixel", "n/a: %s counts nothing per ray", view->request.structure->accel->name().c_str());
      } else {
        row("nodes / pixel", "mean %.2f, max %u", s.mean_nodes, s.max_nodes);
        row("prim tests / pixel", "mean %.2f, max %u", s.mean_prims, s.max_prims);
      }
      if (view->request.structure && view->request.structure->accel && view->request.structure->accel->name() == "tlas")
        row("instances / pixel", "mean %.2f, max %u", s.mean_instances, s.max_instances);
      row("hits", "%" PRIu64 " of %" PRIu64, s.hits, s.rays);
      row("heatmap ms", "%.1f", s.render_ms);
      row("rays / s", "%.3g", s.rays_per_s);
      if (!view->request.shadow_lights.empty()) {
        const bool synthetic = view->request.shadow_lights.front().name == "synthetic";
        row("shadow rays", "%" PRIu64 " (%" PRIu64 " occluded)%s", s.shadow_rays, s.shadowed,
            synthetic ? ", to a synthetic light" : "");
        if (counted) {
          row("nodes / shadow ray", "%.2f", s.mean_shadow_nodes);
          row("prim tests / shadow ray", "%.2f", s.mean_shadow_prims);
        }
      }
      ImGui::EndTable();
    }
  }
  ImGui::End();
}

// ---- View -----------------------------------------------------------------------------------

bool view_panel(ViewSettings& v, const ViewInfo& info, const PanelLayout& layout, QueryOptions* query) {
  bool changed = false;
  if (!begin_panel("View", layout, -kRightColumn, 356, 320, 404)) return false;
  changed |= checkbox("Mesh", v.show_mesh);
  ImGui::SameLine();
  changed |= checkbox("Wireframe", v.show_wireframe);
  ImGui::SameLine();
  changed |= checkbox("Ray path", v.show_ray_path);

  section("Node boxes");
  changed |= checkbox("Boxes", v.show_boxes);
  if (info.node_kind.empty()) {
    ImGui::SameLine();
    ImGui::TextDisabled("(this structure has none)");
  }
  const bool two_level = info.node_kind == "tlas";
  if (two_level) {  // which level's boxes, and per-instance colours
    int level = static_cast<int>(v.box_level);
    if (combo("Level", level, {"top (TLAS)", "bottom (BLASes)"})) {
      v.box_level = static_cast<BoxLevel>(level);
      changed = true;
    }
    if (ImGui::IsItemHovered())
      ImGui::SetTooltip(
          "top: the TLAS nodes, each instance's world box as their leaves; bottom: every instance's BLAS nodes "
          "carried to world space");
    if (v.box_level == BoxLevel::blas) {
      int inst = v.box_instance;
      if (ImGui::InputInt("Instance", &inst)) {
        v.box_instance = std::clamp(
            inst, -1,
            static_cast<int>(std::min<std::uint64_t>(info.instances > 0 ? info.instances - 1 : 0, 0x7FFFFFFF)));
        changed = true;
      }
      ImGui::PushTextWrapPos(0.0f);
      ImGui::TextDisabled("-1: every instance (whole instances up to the box limit)");
      ImGui::PopTextWrapPos();
    }
    changed |= checkbox("Instance colours", v.instance_colors, "each instance's triangles and boxes in its own colour");
  }
  int mode = static_cast<int>(v.box_mode);
  if (combo("Show", mode, {"one depth", "depth range", "leaves", "selected subtree"})) {
    v.box_mode = static_cast<BoxMode>(mode);
    changed = true;
  }
  const int max_depth =
      static_cast<int>(two_level && v.box_level == BoxLevel::blas ? info.blas_max_depth : info.max_depth);
  switch (v.box_mode) {
    case BoxMode::depth:
      changed |= slider_int("Depth", v.box_depth, 0, std::max(max_depth, 1));
      break;
    case BoxMode::depth_range:
      changed |= slider_int("First depth", v.box_depth, 0, std::max(max_depth, 1));
      changed |= slider_int("Last depth", v.box_depth_last, 0, std::max(max_depth, 1));
      if (v.box_depth_last < v.box_depth)
        ImGui::TextDisabled("Last depth is below the first: depth %d alone is drawn", v.box_depth);
      break;
    case BoxMode::leaves:
      break;
    case BoxMode::subtree: {
      int node = v.box_node;
      if (ImGui::InputInt("Node", &node)) {
        v.box_node = std::clamp(
            node, 0,
            static_cast<int>(std::min<std::uint64_t>(info.node_count > 0 ? info.node_count - 1 : 0, 0x7FFFFFFF)));
        changed = true;
      }
      ImGui::PushTextWrapPos(0.0f);
      ImGui::TextDisabled("F frames it; the Ray panel's node ids work here");
      ImGui::PopTextWrapPos();
      if (!info.box_node_note.empty()) {
        ImGui::PushTextWrapPos(0.0f);
        ImGui::TextDisabled("%s", info.box_node_note.c_str());
        ImGui::PopTextWrapPos();
      }
      break;
    }
  }
  int color = static_cast<int>(v.box_color);
  if (combo("Colour by", color, {"depth", "share of the SAH cost"})) {
    v.box_color = static_cast<BoxColorBy>(color);
    changed = true;
  }
  changed |= checkbox("Through mesh", v.boxes_through_mesh, "boxes are not hidden by the mesh");
  if (!info.node_kind.empty()) {
    if (info.boxes_truncated)
      ImGui::TextDisabled("%" PRIu64 " of %" PRIu64 " boxes drawn (list cut)", info.boxes_drawn, info.boxes_matched);
    else
      ImGui::TextDisabled("%" PRIu64 " boxes drawn", info.boxes_drawn);
    const bool by_depth = v.box_mode == BoxMode::depth || v.box_mode == BoxMode::depth_range;
    if (by_depth && info.boxes_matched == 0 && v.box_depth > max_depth)
      ImGui::TextDisabled("no node at depth %d: the deepest is %d", v.box_depth, max_depth);
  }

  section("Heatmap");
  int display = static_cast<int>(v.heatmap);
  bool hm = ImGui::RadioButton("Off", &display, 0);
  ImGui::SameLine();
  hm |= ImGui::RadioButton("Full", &display, 1);
  ImGui::SameLine();
  hm |= ImGui::RadioButton("Blend", &display, 2);
  if (hm) {
    v.heatmap = static_cast<HeatmapDisplay>(display);
    changed = true;
  }
  int metric = static_cast<int>(v.metric);
  if (combo("Metric", metric,
            {"nodes visited", "primitive tests", "cost", "shaded", "hit distance", "instances visited"})) {
    v.metric = static_cast<HeatMetric>(metric);
    changed = true;
  }
  if (const std::string why = metric_not_counted(v.metric, info.structure); !why.empty()) {
    ImGui::PushTextWrapPos(0.0f);
    ImGui::TextDisabled("%s: this metric is 0 everywhere", why.c_str());
    ImGui::PopTextWrapPos();
  } else if (metric_needs_stats(v.metric) && !info.uncounted.empty()) {
    ImGui::PushTextWrapPos(0.0f);
    ImGui::TextDisabled(
        "%s counts nothing per ray: this metric is 0 everywhere (shaded and hit distance show its hits)",
        info.uncounted.c_str());
    ImGui::PopTextWrapPos();
  }
  int device = v.heatmap_gpu ? 1 : 0;
  if (combo("Trace on", device, {"CPU", "GPU"})) {
    v.heatmap_gpu = device == 1;
    changed = true;
  }
  if (v.heatmap_gpu && !info.gpu_note.empty())
    ImGui::TextDisabled("GPU unavailable (%s): traced on the CPU", info.gpu_note.c_str());
  else if (v.heatmap_gpu && info.gpu_rows_done >= 0)
    ImGui::TextDisabled("compute shader: row %d of %d (the previous image stays until done)", info.gpu_rows_done,
                        info.gpu_rows);
  else if (v.heatmap_gpu && info.heatmap_on_gpu)
    ImGui::TextDisabled("compute shader: primary rays, same counts as the CPU");
  int map = static_cast<int>(v.colormap);
  if (combo("Colour map", map, {"viridis", "inferno", "turbo"})) {
    v.colormap = static_cast<ColorMap>(map);
    changed = true;
  }
  if (query) {
    // Same hit in every mode; only the work counted changes (docs/insight.md).
    int order = !query->ordered ? 2 : query->back_to_front ? 1 : 0;
    if (combo("Traversal", order, {"front-to-back", "back-to-front", "unordered"})) {
      query->ordered = order != 2;
      query->back_to_front = order == 1;
      changed = true;
    }
    changed |= checkbox("X-ray", query->xray,
                        "count the full traversal as if no hit ended it (the cost behind the first surface)");
    if (info.node_kind != "bvh" && (query->back_to_front || query->xray))
      ImGui::TextDisabled("back-to-front and x-ray apply to the BVH only; %s ignores them",
                          info.node_kind.empty() ? "this structure" : info.node_kind.c_str());
    else if (info.node_kind != "bvh")
      ImGui::TextDisabled("back-to-front and x-ray: BVH only");
  }
  if (v.heatmap == HeatmapDisplay::blend)
    changed |= ImGui::SliderFloat("Opacity", &v.opacity, 0.0f, 1.0f, "%.2f", ImGuiSliderFlags_AlwaysClamp);
  bool locked = !v.auto_scale;
  if (checkbox("Lock scale", locked, "keep the colour range fixed while the view changes")) {
    v.auto_scale = !locked;
    if (locked) {  // lock at what is shown now
      v.scale_min = info.range_min;
      v.scale_max = info.range_max;
    }
    changed = true;
  }
  if (locked) {
    float r[2] = {v.scale_min, v.scale_max};
    if (ImGui::DragFloat2("Range", r, 0.1f) && r[1] > r[0]) {
      v.scale_min = r[0];
      v.scale_max = r[1];
      changed = true;
    }
    // Values outside a locked range take its end colours: say how far they go.
    const bool above = info.value_max > info.range_max, below = info.value_min < info.range_min;
    if (v.heatmap != HeatmapDisplay::off && (above || below)) {
      ImGui::PushTextWrapPos(0.0f);
      if (above)
        ImGui::TextColored(kWarnColour, "values up to %.4g lie above the range: drawn in its top colour (legend: %s+)",
                           info.value_max, format_tick(info.range_max).c_str());
      if (below)
        ImGui::TextColored(kWarnColour,
                           "values down to %.4g lie below the range: drawn in its bottom colour (legend: <=%s)",
                           info.value_min, format_tick(info.range_min).c_str());
      ImGui::PopTextWrapPos();
    }
  } else {
    ImGui::TextDisabled("range %.4g .. %.4g (auto)", info.range_min, info.range_max);
  }
  changed |= checkbox("Legend", v.show_legend);

  section("Quality");
  int msaa_index = v.msaa >= 8 ? 3 : v.msaa >= 4 ? 2 : v.msaa >= 2 ? 1 : 0;
  if (combo("MSAA", msaa_index, {"off", "2x", "4x", "8x"})) {
    v.msaa = 1 << msaa_index;
    changed = true;
  }
  ImGui::End();
  return changed;
}

// ---- Ray ---------------------------------------------------------------------------------------

std::optional<std::size_t> ray_panel(const RayInspection* ray, std::size_t step, const StructureNodes* nodes,
                                     const PanelLayout& layout) {
  std::optional<std::size_t> moved;
  // Along the bottom edge, between the left and right columns.
  if (!begin_panel("Ray", layout, kMiddleX, 530, middle_width(layout), 230)) return moved;
  if (!ray) {
    ImGui::TextWrapped("Click the 3D view (without dragging) to cast that pixel's ray.");
    ImGui::End();
    return moved;
  }
  // The summary first (pixel, hit, counters); the rest folded, so that the
  // traversal list stays in view in a short window.
  const RayStats& s = ray->stats;
  if (!ray->hit.valid())
    ImGui::Text("pixel %d, %d (%s): miss", ray->x, ray->y, ray->structure.c_str());
  else if (ray->structure == "voxels")  // its hits are voxels: an index into the voxel list, no barycentrics
    ImGui::Text("pixel %d, %d (%s): hit voxel %u at t = %.6g", ray->x, ray->y, ray->structure.c_str(), ray->hit.prim,
                ray->hit.t);
  else
    ImGui::TextWrapped("pixel %d, %d (%s): hit prim %u at t = %.6g", ray->x, ray->y, ray->structure.c_str(),
                       ray->hit.prim, ray->hit.t);
  std::size_t occluded = 0;
  for (const ShadowRay& sh : ray->shadows) occluded += sh.occluded;
  if (ray->shadows.empty())
    ImGui::Text("nodes %u, box tests %u, prim tests %u", s.nodes_visited, s.box_tests, s.prim_tests);
  else
    ImGui::TextWrapped("nodes %u, box tests %u, prim tests %u; shadow rays: %zu lit, %zu occluded", s.nodes_visited,
                       s.box_tests, s.prim_tests, ray->shadows.size() - occluded, occluded);
  if (ImGui::TreeNode("Details")) {
    ImGui::Text("pixel %d, %d of %d x %d", ray->x, ray->y, ray->width, ray->height);
    ImGui::Text("origin    %.5g, %.5g, %.5g", ray->ray.origin.x, ray->ray.origin.y, ray->ray.origin.z);
    ImGui::Text("direction %.5g, %.5g, %.5g", ray->ray.direction.x, ray->ray.direction.y, ray->ray.direction.z);
    if (ray->hit.valid() && ray->structure != "voxels")
      ImGui::Text("barycentrics u = %.4f, v = %.4f", ray->hit.u, ray->hit.v);
    ImGui::Text("culled %u, missed %u, repeated %u, empty cells %u", s.nodes_culled, s.nodes_missed,
                s.repeated_prim_tests, s.empty_cells);
    for (const ShadowRay& sh : ray->shadows)
      ImGui::Text("shadow ray to light %zu%s%s: %s (nodes %u, prim tests %u)", sh.light,
                  sh.light_name.empty() ? "" : " ", sh.light_name.c_str(), sh.occluded ? "occluded" : "lit",
                  sh.stats.nodes_visited, sh.stats.prim_tests);
    ImGui::TreePop();
  }

  const auto& steps = ray->trace.steps;
  if (steps.empty()) {
    ImGui::TextDisabled("no traversal steps (this structure keeps no trace)");
    ImGui::End();
    return moved;
  }
  // The section's rule, its name and the key to the 3D boxes' colours on one line.
  ImGui::Separator();
  ImGui::TextDisabled("Traversal");
  ImGui::SameLine(0.0f, 2.0f * ImGui::GetFontSize());
  visit_fade_key();
  const std::size_t last = steps.size() - 1;
  if (ImGui::ArrowButton("##first", ImGuiDir_Left)) moved = 0;
  ImGui::SameLine();
  if (ImGui::Button("Prev") && step > 0) moved = step - 1;
  ImGui::SameLine();
  if (ImGui::Button("Next") && step < last) moved = step + 1;
  ImGui::SameLine();
  if (ImGui::ArrowButton("##last", ImGuiDir_Right)) moved = last;
  ImGui::SameLine();
  int s_i = static_cast<int>(step);
  ImGui::SetNextItemWidth(-1.0f);
  // The slider names the step's event, so the replay reads without the list below.
  char format[96];
  const VisitStep& now = steps[std::min(step, last)];
  std::snprintf(format, sizeof format, "step %%d/%zu: %s %u", last, step_kind_name(now.kind), now.id);
  if (ImGui::SliderInt("##step", &s_i, 0, static_cast<int>(last), format)) moved = static_cast<std::size_t>(s_i);

  if (ImGui::BeginTable("steps", 5,
                        ImGuiTableFlags_ScrollY | ImGuiTableFlags_RowBg | ImGuiTableFlags_BordersInnerV |
                            ImGuiTableFlags_SizingFixedFit)) {
    ImGui::TableSetupScrollFreeze(0, 1);
    ImGui::TableSetupColumn("#");
    ImGui::TableSetupColumn("event");
    ImGui::TableSetupColumn("id");
    ImGui::TableSetupColumn("t entry / hit");
    ImGui::TableSetupColumn("t exit / box");
    ImGui::TableHeadersRow();
    ImGuiListClipper clipper;
    clipper.Begin(static_cast<int>(steps.size()));
    while (clipper.Step())
      for (int i = clipper.DisplayStart; i < clipper.DisplayEnd; ++i) {
        const VisitStep& st = steps[static_cast<std::size_t>(i)];
        ImGui::TableNextRow();
        ImGui::TableSetColumnIndex(0);
        char label[32];
        std::snprintf(label, sizeof label, "%d", i);
        if (ImGui::Selectable(label, static_cast<std::size_t>(i) == step, ImGuiSelectableFlags_SpanAllColumns))
          moved = static_cast<std::size_t>(i);
        ImGui::TableSetColumnIndex(1);
        ImGui::TextUnformatted(step_kind_name(st.kind));
        // A missed box's t entry above its t exit reads like an error: it is why the box was missed.
        if (ImGui::IsItemHovered()) {
          if (st.kind == VisitStep::Kind::node_missed)
            ImGui::SetTooltip("missed: the ray's slab intervals do not overlap (t entry > t exit), or the box lies "
                              "outside [t min, closest hit]");
          else if (st.kind == VisitStep::Kind::node_culled)
            ImGui::SetTooltip("culled: the box's entry lies beyond the closest hit found so far");
        }
        ImGui::TableSetColumnIndex(2);
        ImGui::Text("%u", st.id);
        ImGui::TableSetColumnIndex(3);
        if (std::isfinite(st.t_entry))
          ImGui::Text("%.5g", st.t_entry);
        else
          ImGui::TextDisabled("-");
        ImGui::TableSetColumnIndex(4);
        const bool box_step = st.kind == VisitStep::Kind::node_entered || st.kind == VisitStep::Kind::node_missed ||
                              st.kind == VisitStep::Kind::node_culled;
        if (box_step && std::isfinite(st.t_exit)) {
          ImGui::Text("%.5g", st.t_exit);
          if (nodes && ImGui::IsItemHovered())
            if (const auto b = nodes->box(st.id))
              ImGui::SetTooltip("box %.4g,%.4g,%.4g .. %.4g,%.4g,%.4g", b->lo.x, b->lo.y, b->lo.z, b->hi.x, b->hi.y,
                                b->hi.z);
        } else {
          ImGui::TextDisabled("-");
        }
      }
    // Keep the current step in view while stepping with the buttons/keys.
    if (moved)
      ImGui::SetScrollY(static_cast<float>(*moved) * ImGui::GetTextLineHeightWithSpacing() -
                        ImGui::GetWindowHeight() * 0.4f);
    ImGui::EndTable();
  }
  ImGui::End();
  return moved;
}

// ---- Screenshot, help, status --------------------------------------------------------------------

bool screenshot_panel(std::string& folder, const std::string& default_folder, const std::string& last_written,
                      const PanelLayout& layout) {
  bool pressed = false;
  if (begin_panel("Screenshot", layout, 8, 684, 340, 76)) {
    ImGui::SetNextItemWidth(-1.0f);
    ImGui::InputTextWithHint("##folder", default_folder.c_str(), &folder);
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("folder for screenshots (empty: %s)", default_folder.c_str());
    pressed = ImGui::Button("Screenshot (F12)");
    if (!last_written.empty()) {
      ImGui::SameLine();
      ImGui::TextDisabled("%s", last_written.c_str());
      if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", last_written.c_str());
    }
    ImGui::End();
  }
  return pressed;
}

void help_panel(bool& open, const PanelLayout& layout) {
  if (!open) return;
  ImGui::SetNextWindowPos(ImVec2(layout.width * 0.5f, layout.height * 0.5f), ImGuiCond_Appearing, ImVec2(0.5f, 0.5f));
  ImGui::SetNextWindowSize(ImVec2(560 * layout.scale, 0), ImGuiCond_Appearing);
  if (ImGui::Begin("Help", &open)) {
    if (ImGui::BeginTable("keys", 2, ImGuiTableFlags_RowBg | ImGuiTableFlags_BordersInnerV)) {
      ImGui::TableSetupColumn("input", ImGuiTableColumnFlags_WidthFixed);
      ImGui::TableSetupColumn("does");
      ImGui::TableHeadersRow();
      for (const Shortcut& s : shortcuts()) {
        ImGui::TableNextRow();
        ImGui::TableSetColumnIndex(0);
        ImGui::TextUnformatted(s.keys.data(), s.keys.data() + s.keys.size());
        ImGui::TableSetColumnIndex(1);
        ImGui::TextUnformatted(s.action.data(), s.action.data() + s.action.size());
      }
      ImGui::EndTable();
    }
    ImGui::TextWrapped(
        "Hovering the view with the heatmap on shows that pixel's figures. Panels keep the mouse "
        "and keyboard while they are hovered or focused. Documentation: docs/gui.md.");
  }
  ImGui::End();
}

namespace {

/// request_window's requests until each panel is drawn: title -> open.
std::map<std::string, bool, std::less<>>& window_requests() {
  static std::map<std::string, bool, std::less<>> requests;
  return requests;
}

bool begin_placed(const char* title, const PanelLayout& layout, bool collapsed, int slot = -1) {
  if (collapsed) ImGui::SetNextWindowCollapsed(true, ImGuiCond_FirstUseEver);
  auto& requests = window_requests();
  if (const auto it = requests.find(std::string_view(title)); it != requests.end()) {
    ImGui::SetNextWindowCollapsed(!it->second, ImGuiCond_Always);
    if (it->second) ImGui::SetNextWindowFocus();
    requests.erase(it);
  }
  const bool open = ImGui::Begin(title);
  follow_display(layout, slot);
  if (open) return true;
  ImGui::End();
  return false;
}

}  // namespace

bool begin_panel(const char* title, const PanelLayout& layout, float x, float y, float w, float h, bool collapsed) {
  place(layout, x, y, w, h);
  return begin_placed(title, layout, collapsed);
}

void request_window(std::string_view title, bool open) {
  window_requests()[std::string(title)] = open;
}

bool covered_by_window(float x0, float y0, float x1, float y1) {
  const ImGuiContext* g = ImGui::GetCurrentContext();
  if (!g) return false;
  for (const ImGuiWindow* w : g->Windows) {
    // Windows begun this frame are Active; the others keep last frame's state in WasActive.
    const bool shown = w->BeginCount > 0 ? w->Active : w->WasActive;
    if (!shown || w->Hidden || w->IsFallbackWindow ||
        (w->Flags & (ImGuiWindowFlags_ChildWindow | ImGuiWindowFlags_Tooltip)))
      continue;
    const ImRect r = w->Rect();
    if (x0 < r.Max.x && r.Min.x < x1 && y0 < r.Max.y && r.Min.y < y1) return true;
  }
  return false;
}

bool begin_stacked_panel(const char* title, const PanelLayout& layout, int slot, float w, float h, bool collapsed) {
  const float s = layout.scale, f = vertical_factor(layout);
  ImGui::SetNextWindowPos(ImVec2(kMiddleX * s, stacked_y(layout, slot)), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(std::min(w, middle_width(layout)) * s, h * s * f), ImGuiCond_FirstUseEver);
  return begin_placed(title, layout, collapsed, slot);
}

bool progress_cancel_row(double fraction, const char* overlay, float bar_width, CancelAt cancel_at) {
  bool cancel = false;
  if (cancel_at == CancelAt::before) {
    cancel = ImGui::Button("Cancel");
    ImGui::SameLine();
  }
  ImGui::ProgressBar(static_cast<float>(fraction), ImVec2(bar_width, 0.0f), overlay);
  if (cancel_at == CancelAt::after) {
    ImGui::SameLine();
    cancel = ImGui::Button("Cancel");
  }
  return cancel;
}

void status_bar(const std::string& message, const std::string& error, const BuildProgress& progress,
                const std::string& heatmap_status, const PanelLayout& layout) {
  const float h = ImGui::GetFrameHeightWithSpacing() + 4.0f * layout.scale;
  ImGui::SetNextWindowPos(ImVec2(0.0f, layout.height - h));
  ImGui::SetNextWindowSize(ImVec2(layout.width, h));
  ImGui::SetNextWindowBgAlpha(0.75f);
  const ImGuiWindowFlags flags = ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove |
                                 ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoFocusOnAppearing |
                                 ImGuiWindowFlags_NoNav | ImGuiWindowFlags_NoBringToFrontOnFocus;
  if (ImGui::Begin("##status", nullptr, flags)) {
    if (progress.busy) {
      ImGui::ProgressBar(static_cast<float>(progress.fraction), ImVec2(160.0f * layout.scale, 0.0f),
                         progress.stage.c_str());
      ImGui::SameLine();
    }
    if (!error.empty())
      ImGui::TextColored(ImVec4(1.0f, 0.4f, 0.35f, 1.0f), "%s", error.c_str());
    else
      ImGui::TextUnformatted(message.c_str());
    if (!heatmap_status.empty()) {
      ImGui::SameLine();
      ImGui::TextDisabled("  (%s)", heatmap_status.c_str());
    }
  }
  ImGui::End();
}

std::string figure_text(double v) {
  char text[48];
  if (std::isfinite(v) && std::fabs(v) >= 1e4 && std::fabs(v) < 1e12)
    std::snprintf(text, sizeof text, "%.0f", v);
  else
    std::snprintf(text, sizeof text, "%.4g", v);
  return text;
}

void pixel_tooltip(int x, int y, const PixelFigures& p, HeatMetric metric, bool exact, std::string_view structure) {
  ImGui::BeginTooltip();
  // Whose figures: after a switch the view shows the structure before until the new one is traced.
  ImGui::Text("pixel %d, %d%s%s%s", x, y, exact ? "" : " (coarse)", structure.empty() ? "" : ", ",
              std::string(structure).c_str());
  const std::string name =
      metric == HeatMetric::nodes ? metric_short_label(metric, structure) : std::string(metric_name(metric));
  if (std::isnan(p.value))
    ImGui::Text("%s: no value", name.c_str());
  else
    ImGui::Text("%s: %s", name.c_str(), figure_text(p.value).c_str());
  ImGui::Text("nodes visited %u, prim tests %u", p.nodes, p.prims);
  if (p.instances > 0) ImGui::Text("instances visited %u", p.instances);
  if (p.prim != kInvalidId)
    ImGui::Text("hit prim %u at t = %.5g", p.prim, p.t);
  else
    ImGui::TextUnformatted("miss");
  ImGui::EndTooltip();
}

}  // namespace accelviz::panels
