// The Tree panel (ui/panels/insight_panels.cpp: tree_panel) drawn headless
// over a small BVH: the root's children show when the root is the selection
// (the default, or a click on a pixel that missed), and a selected leaf opens
// the path to it.
#include <gtest/gtest.h>
#include <imgui.h>
#include <imgui_internal.h>

#include "core/accel/factory.h"
#include "core/scene/load.h"
#include "tests/gl/imgui_headless.h"
#include "ui/app/structure_nodes.h"
#include "ui/panels/insight_panels.h"
#include "ui/panels/panels.h"

namespace accelviz::unity_test_tree_panel {
namespace {

/// Rows the Tree window shows after two frames with `selected` selected: its
/// content height over one row's height, less the two lines above the rows.
int rows_shown(const StructureNodes& nodes, std::uint32_t selected) {
  test::HeadlessImGuiContext ui(ImVec2(1600, 1000));
  panels::request_window("Tree", true);
  bool scroll = false;
  for (int i = 0; i < 2; ++i) {
    ui.begin_frame(ImVec2(-100, -100), false);
    panels::tree_panel(&nodes, nullptr, selected, scroll, panels::PanelLayout{1.0f, 1600, 1000}, ColorMap::viridis, 0,
                       false);
    ImGui::Render();
  }
  const ImGuiWindow* w = ImGui::FindWindowByName("Tree");
  EXPECT_NE(w, nullptr);
  if (!w) return 0;
  EXPECT_FALSE(w->Collapsed);
  const float row = ImGui::GetTextLineHeightWithSpacing();
  return static_cast<int>(w->ContentSize.y / row + 0.5f) - 1;  // the header line above the rows
}

TEST(TreePanel, TheRootIsOpenWhenItIsTheSelection) {
  const Scene s = load_scene("builtin:teapot?size=300");
  const auto bvh = build_accelerator("bvh", s.triangles, StructureOptions{});
  const StructureNodes nodes = StructureNodes::of(*bvh);
  ASSERT_GT(nodes.size(), 7u);
  // The root and its two children at least (it showed the root alone, collapsed).
  EXPECT_GE(rows_shown(nodes, 0), 3);
  // A deep selection opens every node on its path: one row per depth at least.
  std::uint32_t deep = 0;
  for (std::uint32_t i = 0; i < nodes.size(); ++i)
    if (nodes.node(i)->depth > nodes.node(deep)->depth) deep = i;
  EXPECT_GE(rows_shown(nodes, deep), static_cast<int>(nodes.node(deep)->depth) + 1);
}

}  // namespace
}  // namespace accelviz::unity_test_tree_panel

namespace accelviz::unity_test_tree_panel {
namespace {

// A row says visits only where they were counted ("SAH 3.57%0" read as a share of 3.570).
TEST(TreePanel, RowsSayVisitsOnlyWhereCounted) {
  StructureNode inner;
  inner.depth = 0;
  inner.sah_share = 0.0357;
  EXPECT_EQ(panels::tree_row_label(inner, 0, std::nullopt), "node 0  (depth 0, SAH 3.57%)");
  EXPECT_EQ(panels::tree_row_label(inner, 0, 12u), "node 0  (depth 0, SAH 3.57%, visits 12)");
  StructureNode leaf;
  leaf.leaf = true;
  leaf.prims = 4;
  leaf.depth = 10;
  leaf.sah_share = 0.001;
  EXPECT_EQ(panels::tree_row_label(leaf, 10183, std::nullopt), "leaf 10183  (4 prims, depth 10, SAH 0.10%)");
}

}  // namespace
}  // namespace accelviz::unity_test_tree_panel
