// The Robustness panel (ui/panels/robustness_panel.cpp) drawn headless: ImGui
// without a renderer backend (no window, no GL), a real lab result, scripted
// mouse input. Checks that every state draws, that Run (idle) and Cancel
// (busy) report their actions, and that clicking a variant's row selects it
// for the per-ray map.
#include <gtest/gtest.h>
#include <imgui.h>

#include <set>

#include "core/accel/embree_backend.h"
#include "core/analysis/robustness_lab.h"
#include "core/scene/load.h"
#include "tests/core/spatial_test_scenes.h"
#include "tests/gl/imgui_headless.h"
#include "ui/panels/panels.h"

namespace accelviz {
namespace {

struct HeadlessImGui : test::HeadlessImGuiContext {
  panels::RobustnessAction frame(panels::RobustnessPanelState& st, const RobustnessSnapshot* snap, bool busy, ImVec2 at,
                                 bool down) {
    begin_frame(at, down);
    const panels::RobustnessAction a = panels::robustness_panel(st, snap, busy, "kdtree", panels::PanelLayout{});
    ImGui::Render();
    return a;
  }
  panels::RobustnessAction click(panels::RobustnessPanelState& st, const RobustnessSnapshot* snap, bool busy,
                                 ImVec2 at) {
    panels::RobustnessAction a = frame(st, snap, busy, at, true);
    const panels::RobustnessAction b = frame(st, snap, busy, at, false);
    a.run |= b.run;
    a.cancel |= b.cancel;
    return a;
  }
};

/// A finished lab run of `structure` over `triangles` (named `scene`).
RobustnessSnapshot done_snapshot(const std::string& scene, const std::string& structure,
                                 const std::vector<Triangle>& triangles, std::size_t rays) {
  RobustnessSnapshot s;
  s.id = 1;
  s.state = RobustnessSnapshot::State::done;
  s.scene = scene;
  s.structure = structure;
  LabOptions o;
  o.rays = rays;
  o.structure = structure;
  o.threads = 1;
  s.result = run_robustness_lab(triangles, o);
  return s;
}

RobustnessSnapshot done_snapshot() {
  const std::string scene = "builtin:teapot?size=800";
  return done_snapshot(scene, "kdtree", load_scene(scene).triangles, 400);
}

TEST(RobustnessPanel, DrawsEveryStateAndReportsRunAndCancel) {
  HeadlessImGui ui;
  panels::RobustnessPanelState st;
  st.collapsed_at_start = false;
  ui.frame(st, nullptr, false, ImVec2(-100, -100), false);
  RobustnessSnapshot failed;
  failed.state = RobustnessSnapshot::State::failed;
  failed.error = "--structure voxels: voxel hits are voxels";
  ui.frame(st, &failed, false, ImVec2(-100, -100), false);
  RobustnessSnapshot cancelled;
  cancelled.state = RobustnessSnapshot::State::cancelled;
  ui.frame(st, &cancelled, false, ImVec2(-100, -100), false);
  RobustnessSnapshot running;
  ui.frame(st, &running, true, ImVec2(-100, -100), false);

  // Scan below the title bar (a click on its arrow would collapse the window).
  bool run = false, cancel = false;
  for (int y = 112; y < 260 && !run; y += 4)
    for (int x = 380; x < 800 && !run; x += 6)
      run |= ui.click(st, nullptr, false, ImVec2(static_cast<float>(x), static_cast<float>(y))).run;
  for (int y = 112; y < 260 && !cancel; y += 4)
    for (int x = 380; x < 800 && !cancel; x += 6) {
      const panels::RobustnessAction a =
          ui.click(st, &running, true, ImVec2(static_cast<float>(x), static_cast<float>(y)));
      cancel |= a.cancel;
      EXPECT_FALSE(a.run) << "no Run while busy";
    }
  EXPECT_TRUE(run);
  EXPECT_TRUE(cancel);
}

// Rays the structure refuses (Embree's limits: here its float triangle test
// would overflow for the rays from farther out) have their own colour in the
// per-ray map (they were drawn grey, as "ok").
TEST(RobustnessPanel, RaysAStructureRefusesHaveTheirOwnColour) {
  if (!kHaveEmbree) GTEST_SKIP() << "no Embree in this build";
  const RobustnessSnapshot snap =
      done_snapshot("cube", "embree", test_scenes::subdivided_cube(glm::vec3(-2e12f), 4e12f, 3), 200);
  ASSERT_GT(snap.result->structure_rays_refused, 0u);
  ASSERT_GT(snap.result->variants.size(), 4u);
  const auto colour_drawn = [](ImU32 colour) {
    const ImDrawData* d = ImGui::GetDrawData();
    for (int l = 0; l < d->CmdListsCount; ++l)
      for (const ImDrawVert& v : d->CmdLists[l]->VtxBuffer)
        if (v.col == colour) return true;
    return false;
  };
  const ImU32 not_traced = IM_COL32(50, 100, 170, 255);
  HeadlessImGui ui;
  panels::RobustnessPanelState st;
  st.collapsed_at_start = false;
  st.variant = 4;  // Embree's default mode
  for (int i = 0; i < 2; ++i) ui.frame(st, &snap, false, ImVec2(-100, -100), false);
  EXPECT_TRUE(colour_drawn(not_traced));
  st.variant = 0;  // a lab variant traces every ray
  for (int i = 0; i < 2; ++i) ui.frame(st, &snap, false, ImVec2(-100, -100), false);
  EXPECT_FALSE(colour_drawn(not_traced));
}

TEST(RobustnessPanel, ClickingAVariantRowSelectsItForTheMap) {
  const RobustnessSnapshot snap = done_snapshot();
  ASSERT_TRUE(snap.result.has_value());
  ASSERT_EQ(snap.result->variants.size(), 6u);
  HeadlessImGui ui;
  panels::RobustnessPanelState st;
  st.collapsed_at_start = false;
  ui.frame(st, &snap, false, ImVec2(-100, -100), false);
  EXPECT_EQ(st.variant, 3);
  std::set<int> selected;
  for (int y = 150; y < 400; y += 3) {
    ui.click(st, &snap, false, ImVec2(420.0f, static_cast<float>(y)));
    selected.insert(st.variant);
  }
  EXPECT_GE(selected.size(), 5u) << "rows clicked select their variant";
  for (int v : selected) {
    EXPECT_GE(v, 0);
    EXPECT_LT(v, 6);
  }
}

}  // namespace
}  // namespace accelviz
