// The Cost of accuracy panel (ui/panels/accuracy_panel.cpp) drawn headless:
// ImGui without a renderer backend (no window, no GL), a real sweep's
// snapshot, and scripted mouse input. Checks that the panel draws every
// state, that clicking on its charts applies a measured setting (and only
// that), and that the Run and Cancel buttons report their actions.
#include <gtest/gtest.h>
#include <imgui.h>

#include <memory>
#include <set>

#include "core/query/camera.h"
#include "core/scene/load.h"
#include "tests/gl/imgui_headless.h"
#include "ui/panels/panels.h"

namespace accelviz {
namespace {

struct HeadlessImGui : test::HeadlessImGuiContext {
  // A press frame and a release frame at `at` (charts act on the press, buttons on the release).
  panels::AccuracyAction click(panels::AccuracyPanelState& st, const SweepSnapshot* snap, bool busy, ImVec2 at) {
    panels::AccuracyAction a = frame(st, snap, busy, at, true);
    const panels::AccuracyAction b = frame(st, snap, busy, at, false);
    a.run |= b.run;
    a.cancel |= b.cancel;
    if (b.apply) {
      a.apply = b.apply;
      a.apply_structure = b.apply_structure;
    }
    return a;
  }
  // One frame with the mouse at `at`, the left button down or not.
  panels::AccuracyAction frame(panels::AccuracyPanelState& st, const SweepSnapshot* snap, bool busy, ImVec2 at,
                               bool down) {
    begin_frame(at, down);
    const panels::AccuracyAction a = panels::accuracy_panel(st, snap, busy, "bvh", panels::PanelLayout{});
    ImGui::Render();
    return a;
  }
};

std::shared_ptr<const SweepSnapshot> small_sweep() {
  SweepRequest r;
  auto scene = std::make_shared<LoadedScene>();
  scene->spec = "builtin:teapot?size=800";
  scene->scene = load_scene(scene->spec);
  r.scene = scene;
  r.params = parse_sweep_params_text("bvh", "buckets=2,8,exact leaf=1,4");
  r.camera = frame_bounds(scene->scene.bounds(), 1.5f);
  r.width = 24;
  r.height = 16;
  r.threads = 1;
  return run_sweep_request(r, 1, {}, {});
}

TEST(AccuracyPanel, ClickingTheChartsAppliesAMeasuredSetting) {
  const auto snap = small_sweep();
  ASSERT_EQ(snap->state, SweepSnapshot::State::done);
  ASSERT_EQ(snap->results.size(), 6u);
  std::set<std::string> measured;
  for (const SweepResult& r : snap->results) measured.insert(setting_label(r.setting));

  HeadlessImGui ui;
  panels::AccuracyPanelState st;
  st.collapsed_at_start = false;
  ui.frame(st, snap.get(), false, ImVec2(-100, -100), false);  // lay out once
  EXPECT_EQ(st.params, default_sweep_params_text("bvh"));

  // Click over a lattice of the window (press one frame, release the next).
  int applied = 0;
  for (int y = 90; y < 700; y += 9)
    for (int x = 356; x < 916; x += 9) {
      const panels::AccuracyAction a =
          ui.click(st, snap.get(), false, ImVec2(static_cast<float>(x), static_cast<float>(y)));
      if (!a.apply) continue;  // (the scan also presses Run; the caller would start a sweep)
      ++applied;
      EXPECT_EQ(a.apply_structure, "bvh");
      EXPECT_TRUE(measured.count(setting_label(*a.apply))) << setting_label(*a.apply);
      StructureChoice c;
      EXPECT_EQ(apply_sweep_point(c, a.apply_structure, *a.apply), "");
    }
  EXPECT_GT(applied, 0) << "no click on the charts applied a setting";

  // Outside the window nothing is applied.
  EXPECT_FALSE(ui.click(st, snap.get(), false, ImVec2(1200, 780)).apply);
}

TEST(AccuracyPanel, DrawsEveryStateAndReportsRunAndCancel) {
  HeadlessImGui ui;
  panels::AccuracyPanelState st;
  st.collapsed_at_start = false;
  // No sweep yet; then a failed and a running snapshot with a calibration report.
  ui.frame(st, nullptr, false, ImVec2(-100, -100), false);
  SweepSnapshot failed;
  failed.state = SweepSnapshot::State::failed;
  failed.error = "no scene loaded";
  ui.frame(st, &failed, false, ImVec2(-100, -100), false);
  SweepSnapshot running = *small_sweep();
  running.state = SweepSnapshot::State::running;
  running.results.resize(2);
  CalibrationReport cal;
  cal.machine.ns_box = 2;
  cal.machine.ns_triangle_watertight = 6;
  cal.c_isect = 1.5;
  running.calibration = cal;
  ui.frame(st, &running, true, ImVec2(-100, -100), false);

  // Find the buttons by scanning the top of the window below its title bar
  // (a click on the title's arrow would collapse it): Run and Cancel (enabled while busy).
  bool run = false, cancel = false;
  for (int y = 130; y < 400 && !(run && cancel); y += 4)
    for (int x = 356; x < 700 && !(run && cancel); x += 6) {
      const panels::AccuracyAction a =
          ui.click(st, &running, true, ImVec2(static_cast<float>(x), static_cast<float>(y)));
      run |= a.run;
      cancel |= a.cancel;
    }
  EXPECT_TRUE(run);
  EXPECT_TRUE(cancel);
}

}  // namespace
}  // namespace accelviz
