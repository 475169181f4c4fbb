// The Stats panel (ui/panels/panels.cpp: stats_panel) drawn headless: after a
// structure switch, the view's figures still come from the structure before
// until the new one's first level is traced, and the panel says whose they are
// (a K-D tree's heading over the BVH's nodes per pixel read as the K-D tree's).
#include <gtest/gtest.h>
#include <imgui.h>
#include <imgui_internal.h>

#include "core/accel/factory.h"
#include "core/scene/load.h"
#include "tests/gl/imgui_headless.h"
#include "ui/app/build_worker.h"
#include "ui/app/heatmap_worker.h"
#include "ui/panels/panels.h"

namespace accelviz::unity_test_stats_panel {
namespace {

std::shared_ptr<BuiltStructure> built(const std::shared_ptr<LoadedScene>& scene, const std::string& name) {
  auto b = std::make_shared<BuiltStructure>();
  b->scene = scene;
  b->choice.name = name;
  b->accel = build_accelerator(name, scene->scene.triangles, StructureOptions{});
  return b;
}

/// The Stats window's content height after two frames showing `shown` over `view`, in text lines.
float content_lines(const BuiltStructure* shown, const HeatmapFrame& view) {
  test::HeadlessImGuiContext ui(ImVec2(1600, 1000));
  for (int i = 0; i < 2; ++i) {
    ui.begin_frame(ImVec2(-100, -100), false);
    panels::stats_panel(shown, &view, panels::PanelLayout{1.0f, 1600, 1000});
    ImGui::Render();
  }
  const ImGuiWindow* w = ImGui::FindWindowByName("Stats");
  EXPECT_NE(w, nullptr);
  return w ? w->ContentSize.y / ImGui::GetTextLineHeight() : 0.0f;
}

TEST(StatsPanel, FiguresOfTheStructureBeforeAreSaidToBeIts) {
  auto scene = std::make_shared<LoadedScene>();
  scene->scene = load_scene("builtin:teapot?size=300");
  // A rebuild of the same structure (a knob moved): the same rows, but the view is the old tree's.
  const auto bvh = built(scene, "bvh"), rebuilt = built(scene, "bvh");
  HeatmapFrame view;
  view.request.structure = bvh;
  view.image.width = view.image.height = 8;
  view.complete = true;
  const float same = content_lines(bvh.get(), view), switched = content_lines(rebuilt.get(), view);
  // One more line over the figures: "of bvh, the structure before: ...".
  EXPECT_GT(switched, same + 0.5f);
}

}  // namespace
}  // namespace accelviz::unity_test_stats_panel
