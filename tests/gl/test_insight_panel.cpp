// The Predicted vs measured panel (ui/panels/insight_panels.cpp) drawn
// headless: ImGui without a renderer backend (no window, no GL), a real view
// insight of a BVH, scripted mouse input. A drag across the record image
// selects that rectangle of the record's pixels as the heatmap region, and
// the region's figures are drawn without error.
#include <gtest/gtest.h>
#include <imgui.h>

#include <atomic>

#include "core/accel/factory.h"
#include "core/scene/load.h"
#include "tests/gl/imgui_headless.h"
#include "ui/panels/insight_panels.h"

namespace accelviz {
namespace {

struct InsightPanelHarness : test::HeadlessImGuiContext {
  InsightPanelHarness() : HeadlessImGuiContext(ImVec2(1280, 1600)) {}
  void frame(panels::InsightPanelState& st, const ViewInsight* v, const RegionTouch* region, ImVec2 at, bool down) {
    begin_frame(at, down);
    // Open and tall enough to show the record image (the panel starts collapsed).
    ImGui::SetWindowCollapsed("Predicted vs measured", false);
    ImGui::SetWindowPos("Predicted vs measured", ImVec2(10, 10));
    ImGui::SetWindowSize("Predicted vs measured", ImVec2(600, 1500));
    panels::insight_panel(st, v, region, false, "", 0, panels::PanelLayout{});
    ImGui::Render();
  }
};

ViewInsight teapot_insight() {
  auto loaded = std::make_shared<LoadedScene>();
  loaded->scene = load_scene("builtin:teapot?size=800");
  auto built = std::make_shared<BuiltStructure>();
  built->scene = loaded;
  built->accel = build_accelerator("bvh", loaded->scene.triangles, StructureOptions{});
  built->nodes = StructureNodes::of(*built->accel);
  ViewInsightRequest r;
  r.built = built;
  r.camera = look_at({6.0f, 4.0f, 8.0f}, {0.0f, 1.2f, 0.0f}, 0.7f);
  r.width = 64;
  r.height = 48;
  r.threads = 1;
  const std::atomic<bool> cancel{false};
  return run_view_insight(r, cancel);
}

TEST(InsightPanel, DraggingOnTheRecordImageSelectsARegion) {
  const ViewInsight v = teapot_insight();
  InsightPanelHarness ui;
  panels::InsightPanelState st;
  const ImVec2 away(-100, -100);
  ui.frame(st, &v, nullptr, away, false);
  ui.frame(st, &v, nullptr, away, false);
  ASSERT_GT(st.image_cell, 0.0f) << "the record image was not drawn";
  EXPECT_FALSE(st.region);
  const auto at = [&](float x, float y) {
    return ImVec2(st.image_x + (x + 0.5f) * st.image_cell, st.image_y + (y + 0.5f) * st.image_cell);
  };
  // Press on record pixel (10, 8), drag to (40, 30), release.
  ui.frame(st, &v, nullptr, at(10, 8), false);
  ui.frame(st, &v, nullptr, at(10, 8), true);
  ui.frame(st, &v, nullptr, at(25, 20), true);
  ui.frame(st, &v, nullptr, at(40, 30), true);
  EXPECT_FALSE(st.region) << "set on release";
  ui.frame(st, &v, nullptr, at(40, 30), false);
  ASSERT_TRUE(st.region);
  EXPECT_EQ(st.region->x0, 10);
  EXPECT_EQ(st.region->y0, 8);
  EXPECT_EQ(st.region->x1, 41);
  EXPECT_EQ(st.region->y1, 31);
  // Its figures draw; a drag the other way round gives the same rectangle.
  const RegionTouch touched = region_touch(v.record, st.region->x0, st.region->y0, st.region->x1, st.region->y1);
  EXPECT_GT(touched.nodes.size(), 0u);
  ui.frame(st, &v, &touched, away, false);
  st.region.reset();
  ui.frame(st, &v, nullptr, at(40, 30), true);
  ui.frame(st, &v, nullptr, at(10, 8), true);
  ui.frame(st, &v, nullptr, at(10, 8), false);
  ASSERT_TRUE(st.region);
  EXPECT_EQ(st.region->x0, 10);
  EXPECT_EQ(st.region->x1, 41);
}

}  // namespace
}  // namespace accelviz
