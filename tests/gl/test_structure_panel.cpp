// The Structure panel (ui/panels/panels.cpp) drawn headless: ImGui without a
// renderer backend, scripted clicks over the panel. A tlas takes the BVH's
// options for each BLAS and the TLAS, so its panel has the BVH's widgets:
// clicks there change the BVH options; a structure without those widgets
// (brute force) leaves them as they were.
#include <gtest/gtest.h>
#include <imgui.h>

#include <string>

#include "tests/gl/imgui_headless.h"
#include "ui/panels/panels.h"

namespace accelviz::unity_test_structure_panel {
namespace {

bool same(const BvhOptions& a, const BvhOptions& b) {
  return a.splitter == b.splitter && a.buckets == b.buckets && a.max_leaf_size == b.max_leaf_size &&
         a.leaf_size_cap == b.leaf_size_cap && a.cost_traversal == b.cost_traversal &&
         a.cost_intersect == b.cost_intersect && a.compute_epo == b.compute_epo;
}

struct StructurePanelUi : test::HeadlessImGuiContext {
  bool frame(StructureChoice& c, ImVec2 at, bool down) {
    begin_frame(at, down);
    bool cancel = false;
    const bool changed = panels::structure_panel(c, panels::BuildProgress{}, cancel, panels::PanelLayout{});
    ImGui::Render();
    return changed;
  }
};

/// Clicks down the panel below its Type row (a click there would open the
/// type list); returns whether any click changed the BVH options while the
/// type stayed `name`.
bool clicks_change_bvh_options(const std::string& name) {
  StructurePanelUi ui;
  StructureChoice c;
  c.name = name;
  const BvhOptions before = c.options.bvh;
  ui.frame(c, ImVec2(-100, -100), false);
  for (int y = 330; y < 560; y += 4)
    for (const float x : {160.0f, 250.0f}) {
      ui.frame(c, ImVec2(x, static_cast<float>(y)), true);
      ui.frame(c, ImVec2(x, static_cast<float>(y)), false);
      EXPECT_EQ(c.name, name) << "the clicks stay below the Type row";
      if (!same(c.options.bvh, before)) return true;
    }
  return false;
}

TEST(StructurePanel, TlasShowsTheBvhOptionsItsLevelsAreBuiltWith) {
  EXPECT_TRUE(clicks_change_bvh_options("bvh"));
  EXPECT_TRUE(clicks_change_bvh_options("tlas"));
  EXPECT_FALSE(clicks_change_bvh_options("brute"));
}

// Panel figures keep whole numbers whole from 1e4 on (%.4g printed 20000 prim tests as "2e+04" beside
// "prim tests 20000", and an SAH cost of 30000 as "3e+04").
TEST(PanelFigures, LargeFiguresStayWhole) {
  EXPECT_EQ(panels::figure_text(20000.0), "20000");
  EXPECT_EQ(panels::figure_text(30001.4), "30001");
  EXPECT_EQ(panels::figure_text(24.1304), "24.13");
  EXPECT_EQ(panels::figure_text(0.5), "0.5");
  EXPECT_EQ(panels::figure_text(2e13), "2e+13");
}

}  // namespace
}  // namespace accelviz::unity_test_structure_panel
