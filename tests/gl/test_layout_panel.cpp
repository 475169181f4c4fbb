// The panels' first-use layout (ui/panels/panels.cpp: place, begin_panel,
// begin_stacked_panel, follow_display) drawn headless: the real panels in a
// 1280×800 window, then the window resized. The columns stay clear of each
// other and of the status line, the insight windows' collapsed title bars
// neither overlap one another nor the columns, and a resize carries the
// right column with the right edge and scales every panel with the height.
#include <gtest/gtest.h>
#include <imgui.h>
#include <imgui_internal.h>

#include <string>
#include <vector>

#include "tests/gl/imgui_headless.h"
#include "ui/app/window_titles.h"
#include "ui/panels/insight_panels.h"
#include "ui/panels/panels.h"

namespace accelviz::unity_test_layout_panel {
namespace {

struct Rect {
  float x0, y0, x1, y1;
};

Rect rect_of(const char* title) {
  const ImGuiWindow* w = ImGui::FindWindowByName(title);
  EXPECT_NE(w, nullptr) << title;
  if (!w) return {0, 0, 0, 0};
  // A collapsed window occupies its title bar only.
  const float h = w->Collapsed ? w->TitleBarHeight() : w->Size.y;
  return {w->Pos.x, w->Pos.y, w->Pos.x + w->Size.x, w->Pos.y + h};
}

bool overlap(const Rect& a, const Rect& b) {
  return a.x0 < b.x1 && b.x0 < a.x1 && a.y0 < b.y1 && b.y0 < a.y1;
}

const char* const kColumns[] = {"Scene", "Structure", "Screenshot", "Stats", "View", "Ray"};
const char* const kStacked[] = {"A/B compare", "Predicted vs measured", "SAH explainer",
                                "Tree",        "Cost of accuracy",      "Robustness",
                                "Scenarios",   "Flatten what-if"};

struct Ui : test::HeadlessImGuiContext {
  Ui() : HeadlessImGuiContext(ImVec2(1600, 1000)) {}

  panels::ViewInfo info;
  ViewSettings view;
  StructureChoice choice;
  std::string path, folder;
  panels::ABPanelState ab;
  panels::InsightPanelState insight;
  panels::ExplainerState explainer;
  panels::ScenarioPanelState scenarios;
  panels::AccuracyPanelState accuracy;
  panels::RobustnessPanelState robustness;
  panels::FlattenPanelState flatten;
  DynamicsPlayer player;
  bool cancel = false, scroll = false;

  bool with_flatten = true;    ///< the Flatten what-if is drawn only while a tlas is shown
  bool with_dynamics = false;  ///< the Dynamics panel only while per-frame updates are on

  /// Every panel of the layout in a window of w × h.
  void frame(float w, float h) {
    ImGui::GetIO().DisplaySize = ImVec2(w, h);  // ImGui pulls windows a smaller display would hide into it
    begin_frame(ImVec2(-100, -100), false);
    const panels::PanelLayout l{1.0f, w, h};
    panels::scene_panel(path, {}, nullptr, "", -1, l);
    panels::structure_panel(choice, panels::BuildProgress{}, cancel, l);
    panels::stats_panel(nullptr, nullptr, l);
    panels::view_panel(view, info, l);
    panels::ray_panel(nullptr, 0, nullptr, l);
    panels::screenshot_panel(folder, "/tmp", "", l);
    panels::ab_panel(ab, nullptr, false, "", choice, l);
    panels::insight_panel(insight, nullptr, nullptr, false, "", 0, l);
    panels::explainer_panel(explainer, nullptr, 0, "", l);
    panels::tree_panel(nullptr, nullptr, 0, scroll, l, ColorMap::viridis, 0, false);
    panels::scenarios_panel(scenarios, nullptr, false, "", l);
    panels::accuracy_panel(accuracy, nullptr, false, "bvh", l);
    panels::robustness_panel(robustness, nullptr, false, "bvh", l);
    if (with_flatten) panels::flatten_panel(flatten, nullptr, nullptr, false, 0.0, std::nullopt, l);
    if (with_dynamics) panels::dynamics_panel(player, nullptr, false, l);
    ImGui::Render();
  }

  void expect_tidy(float w, float h) {
    SCOPED_TRACE(std::to_string(static_cast<int>(w)) + "x" + std::to_string(static_cast<int>(h)));
    const float status_top = h - ImGui::GetFrameHeightWithSpacing() - 4.0f;
    std::vector<Rect> columns;
    for (const char* c : kColumns) {
      const Rect r = rect_of(c);
      EXPECT_GE(r.x0, 0.0f) << c;
      EXPECT_LE(r.x1, w) << c;
      EXPECT_GE(r.y0, 0.0f) << c;
      EXPECT_LE(r.y1, status_top + 0.5f) << c << " runs into the status line";
      for (std::size_t i = 0; i < columns.size(); ++i)
        EXPECT_FALSE(overlap(r, columns[i])) << c << " overlaps " << kColumns[i];
      columns.push_back(r);
    }
    std::vector<Rect> bars;
    for (const char* t : kStacked) {
      if (!with_flatten && std::string(t) == "Flatten what-if") continue;
      const Rect r = rect_of(t);
      for (std::size_t i = 0; i < bars.size(); ++i)
        EXPECT_FALSE(overlap(r, bars[i])) << t << " overlaps " << kStacked[i];
      for (std::size_t i = 0; i < columns.size(); ++i)
        EXPECT_FALSE(overlap(r, columns[i])) << t << " overlaps " << kColumns[i];
      bars.push_back(r);
    }
  }
};

TEST(PanelLayout, ColumnsAndCollapsedInsightWindowsStayApartAndFollowAResize) {
  Ui ui;
  ui.flatten.collapsed_at_start = true;
  for (int i = 0; i < 3; ++i) ui.frame(1280, 800);
  ui.expect_tidy(1280, 800);
  const Rect stats = rect_of("Stats");
  EXPECT_FLOAT_EQ(1280.0f - stats.x0, 438.0f);

  // Larger: the right column keeps its distance to the right edge; the
  // others keep theirs to the left; every panel scales with the height.
  for (int i = 0; i < 3; ++i) ui.frame(1600, 1000);
  ui.expect_tidy(1600, 1000);
  EXPECT_FLOAT_EQ(1600.0f - rect_of("Stats").x0, 438.0f);
  EXPECT_FLOAT_EQ(rect_of("Scene").x0, 8.0f);
  EXPECT_NEAR(rect_of("View").y1 - rect_of("View").y0, 404.0f * 1000.0f / 800.0f, 1.0f);

  // Smaller than designed for: nothing runs off the window or into the status line.
  for (int i = 0; i < 3; ++i) ui.frame(1280, 720);
  ui.expect_tidy(1280, 720);
}

// A window narrower than designed for (a 1024×768 projector) on first use: the insight windows and the
// Ray panel take the strip left between the columns, so nothing covers the Stats or View panels (the
// insight title bars lay over Stats, the Ray panel over the View panel's controls).
TEST(PanelLayout, ANarrowWindowFirstOpensWithoutOverlaps) {
  Ui ui;
  ui.flatten.collapsed_at_start = true;
  for (int i = 0; i < 3; ++i) ui.frame(1024, 768);
  ui.expect_tidy(1024, 768);
  EXPECT_FLOAT_EQ(panels::middle_width(panels::PanelLayout{1.0f, 1024, 768}), 222.0f);
  EXPECT_FLOAT_EQ(panels::middle_width(panels::PanelLayout{1.0f, 1280, 800}), 470.0f);
}

// Made narrower after opening (a script's `size 1024 768`, a window dragged onto a projector): the
// strip's windows narrow with it, and take their width back when the window grows again.
TEST(PanelLayout, ANarrowedWindowNarrowsTheMiddleStrip) {
  Ui ui;
  ui.flatten.collapsed_at_start = true;
  for (int i = 0; i < 3; ++i) ui.frame(1280, 800);
  const float ray_width = rect_of("Ray").x1 - rect_of("Ray").x0;
  for (int i = 0; i < 3; ++i) ui.frame(1024, 768);
  ui.expect_tidy(1024, 768);
  for (int i = 0; i < 3; ++i) ui.frame(1280, 800);
  ui.expect_tidy(1280, 800);
  EXPECT_FLOAT_EQ(rect_of("Ray").x1 - rect_of("Ray").x0, ray_width);
}

// Resizes in a row (one frame each, as a window drag gives) and back again
// keep the layout tidy, and a window first drawn after a resize (the Flatten
// what-if appears with a tlas) joins the stack in its place.
TEST(PanelLayout, RepeatedResizesAndALateWindowKeepTheLayoutTidy) {
  Ui ui;
  ui.flatten.collapsed_at_start = true;
  ui.with_flatten = false;
  for (int i = 0; i < 2; ++i) ui.frame(1280, 800);
  const float sizes[][2] = {{1600, 1000}, {1280, 720}, {1600, 1000}, {1280, 720}, {1400, 900}};
  for (const auto& s : sizes) ui.frame(s[0], s[1]);  // one frame each
  for (int i = 0; i < 2; ++i) ui.frame(1400, 900);
  ui.expect_tidy(1400, 900);
  for (const auto& s : sizes)
    for (int i = 0; i < 3; ++i) ui.frame(s[0], s[1]);
  ui.expect_tidy(1400, 900);
  ui.with_flatten = true;
  for (int i = 0; i < 3; ++i) ui.frame(1400, 900);
  ui.expect_tidy(1400, 900);
  for (int i = 0; i < 3; ++i) ui.frame(1280, 720);
  ui.expect_tidy(1280, 720);
}

// A window opened at another size than the design's gets the layout at its
// own size on first use (the vertical positions and heights scaled).
TEST(PanelLayout, FirstUseInASmallerWindowFitsIt) {
  Ui ui;
  ui.flatten.collapsed_at_start = true;
  for (int i = 0; i < 3; ++i) ui.frame(1280, 720);
  ui.expect_tidy(1280, 720);
}

// A script's `window open|close TITLE` names the panels by kPanelTitles:
// each is a panel the app draws, and a request expands or collapses it the
// next time it is drawn (pin-a and scenario open their windows so).
TEST(PanelLayout, EveryPanelTitleIsDrawnAndWindowRequestsOpenAndCloseIt) {
  Ui ui;
  ui.with_dynamics = true;
  for (int i = 0; i < 2; ++i) ui.frame(1280, 800);
  for (const std::string_view t : kPanelTitles)
    EXPECT_NE(ImGui::FindWindowByName(std::string(t).c_str()), nullptr) << t;
  const auto collapsed = [](const char* t) { return ImGui::FindWindowByName(t)->Collapsed; };
  ASSERT_TRUE(collapsed("Tree"));  // the insight windows start collapsed
  panels::request_window("Tree", true);
  ui.frame(1280, 800);
  EXPECT_FALSE(collapsed("Tree"));
  ui.frame(1280, 800);
  EXPECT_FALSE(collapsed("Tree")) << "a request is applied once, then the user's clicks rule";
  panels::request_window("Tree", false);
  panels::request_window("Scene", false);
  ui.frame(1280, 800);
  EXPECT_TRUE(collapsed("Tree"));
  EXPECT_TRUE(collapsed("Scene"));
  // A request for a panel not drawn now waits for it.
  panels::request_window("Dynamics", true);
  ui.frame(1280, 800);
  ASSERT_FALSE(collapsed("Dynamics"));
  ui.with_dynamics = false;
  ui.frame(1280, 800);
  panels::request_window("Dynamics", false);
  ui.frame(1280, 800);
  ui.with_dynamics = true;
  ui.frame(1280, 800);
  EXPECT_TRUE(collapsed("Dynamics"));
}

// What the 3D view draws behind the windows (hot-node labels) is left out
// where a window covers it: an open window by its whole rectangle, a
// collapsed one by its title bar, a window not drawn this frame by last
// frame's place, and no longer once it is closed.
TEST(PanelLayout, CoveredByWindowFollowsOpenCollapsedAndClosedWindows) {
  test::HeadlessImGuiContext ctx(ImVec2(800, 600));
  const auto window = [](const char* title, ImVec2 pos, bool collapsed) {
    ImGui::SetNextWindowPos(pos, ImGuiCond_Always);
    ImGui::SetNextWindowSize(ImVec2(200, 300), ImGuiCond_Always);
    ImGui::SetNextWindowCollapsed(collapsed, ImGuiCond_Always);
    ImGui::Begin(title);
    ImGui::End();
  };
  const auto covered = [](float x, float y) { return panels::covered_by_window(x, y, x + 20, y + 10); };
  for (int i = 0; i < 2; ++i) {
    ctx.begin_frame(ImVec2(-100, -100), false);
    window("Open", ImVec2(100, 100), false);
    window("Folded", ImVec2(500, 100), true);
    EXPECT_TRUE(covered(150, 350));   // inside Open
    EXPECT_TRUE(covered(90, 95));     // overlaps Open's corner
    EXPECT_FALSE(covered(350, 200));  // between the two
    EXPECT_TRUE(covered(550, 102));   // Folded's title bar
    EXPECT_FALSE(covered(550, 200));  // below Folded's title bar: its body is not drawn
    ImGui::Render();
  }
  // The next frame, before the windows are begun: last frame's places.
  ctx.begin_frame(ImVec2(-100, -100), false);
  EXPECT_TRUE(covered(150, 350));
  EXPECT_TRUE(covered(550, 102));
  window("Folded", ImVec2(500, 100), true);
  ImGui::Render();
  // Open was not drawn in that frame: it is closed now.
  ctx.begin_frame(ImVec2(-100, -100), false);
  EXPECT_FALSE(covered(150, 350));
  EXPECT_TRUE(covered(550, 102));
  ImGui::Render();
}

}  // namespace
}  // namespace accelviz::unity_test_layout_panel
