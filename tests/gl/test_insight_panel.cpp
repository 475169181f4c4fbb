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
#include "ui/app/insight_jobs.h"
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

/// A and B (bvh, default options) over an 800-triangle teapot, 32 x 24 pixels, one thread.
ABRequest teapot_ab() {
  auto loaded = std::make_shared<LoadedScene>();
  loaded->scene = load_scene("builtin:teapot?size=800");
  ABRequest r;
  r.scene = loaded;
  r.camera = look_at({6.0f, 4.0f, 8.0f}, {0.0f, 1.2f, 0.0f}, 0.7f);
  r.width = 32;
  r.height = 24;
  r.threads = 1;
  return r;
}

TEST(InsightJobs, ABCostMetricWeighsEachSideWithItsOwnSahCosts) {
  // The A/B compare's cost image is c_trav * nodes + c_isect * prims with
  // the side's own costs (as the view and render --compare), not 1 and 1.
  ABRequest r = teapot_ab();
  r.a.options.bvh.cost_traversal = 2.0f;
  r.a.options.bvh.cost_intersect = 3.0f;
  r.b = r.a;
  const std::atomic<bool> cancel{false};
  const auto image = [&](HeatMetric m) {
    r.metric = m;
    return run_ab(r, cancel).image_a;
  };
  const MetricImage cost = image(HeatMetric::cost), nodes = image(HeatMetric::nodes), prims = image(HeatMetric::prims);
  ASSERT_EQ(cost.values.size(), nodes.values.size());
  double total = 0.0;
  for (std::size_t i = 0; i < cost.values.size(); ++i) {
    EXPECT_FLOAT_EQ(cost.values[i], 2.0f * nodes.values[i] + 3.0f * prims.values[i]) << i;
    total += prims.values[i];
  }
  EXPECT_GT(total, 0.0);  // some rays test triangles: the weights matter
}

TEST(InsightJobs, ABTimesEachSidesClosestHitsAndCountsTheHitsThatChanged) {
  // The same choice on both sides: the same hits, none changed, each side timed.
  ABRequest r = teapot_ab();
  r.b.name = "grid";
  const std::atomic<bool> cancel{false};
  const ABResult res = run_ab(r, cancel);
  EXPECT_GT(res.hits_a, 0u);
  EXPECT_LT(res.hits_a, 32u * 24u);  // the view also shows background
  EXPECT_EQ(res.hits_b, res.hits_a);
  EXPECT_EQ(res.hits_changed, 0u);  // a grid finds the BVH's closest hits
  EXPECT_GT(res.trace_ms_a, 0.0);
  EXPECT_GT(res.trace_ms_b, 0.0);
  EXPECT_GT(res.sah_a, 0.0);
  EXPECT_EQ(res.sah_b, 0.0);  // a grid reports no SAH (the panel says n/a)
}

#ifdef ACCELVIZ_HAVE_EMBREE
TEST(InsightJobs, ABWithASideThatCountsNothingSaysSo) {
  // Embree counts nothing per ray: its images are 0, so no count compares (the panel and dump-ab say
  // so); its closest hits are still timed and compared.
  ABRequest r = teapot_ab();
  r.b.name = "embree";
  const std::atomic<bool> cancel{false};
  const ABResult res = run_ab(r, cancel);
  EXPECT_EQ(res.uncounted, "embree");
  EXPECT_EQ(res.figures.total_b, 0.0);
  EXPECT_GT(res.hits_b, 0u);
  EXPECT_LE(res.hits_changed, res.hits_a / 20);  // a few edge pixels at most: the same scene
  r.b.name = "kdtree";
  EXPECT_EQ(run_ab(r, cancel).uncounted, "");
}
#endif

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
