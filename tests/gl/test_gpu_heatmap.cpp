// The GUI's GPU heatmap (app/gui/gpu_heatmap.cpp, the View panel's "Trace
// on: GPU"): its frame is made in one pass over the pixels read in place from
// the GPU, and a frame the window no longer holds is written over instead of
// allocated again. Each frame must hold, pixel for pixel and field for field,
// what the CPU worker's complete frame holds for the same request, whatever
// image the frame held before. On llvmpipe (OSMesa); tiny images.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <memory>
#include <string>

#include "app/gui/gpu_heatmap.h"
#include "core/accel/bvh/bvh.h"
#include "core/query/camera.h"
#include "core/scene/load.h"
#include "ui/gl/headless.h"

namespace accelviz::test {
namespace gpu_heatmap_test {

/// The CPU worker's complete frame of `r` (its last level).
std::shared_ptr<const HeatmapFrame> cpu_frame(const HeatmapRequest& r) {
  std::shared_ptr<const HeatmapFrame> last;
  trace_progressive(
      r, 0, [] { return true; }, [&](std::shared_ptr<const HeatmapFrame> f) { last = std::move(f); });
  return last;
}

bool same_bits(float a, float b) {
  return std::bit_cast<std::uint32_t>(a) == std::bit_cast<std::uint32_t>(b);
}

/// Every pixel's figures and value, and the summary, as the CPU's.
void expect_frame_as_cpu(const HeatmapFrame& gpu, const HeatmapRequest& r, std::uint64_t id, const std::string& what) {
  const std::shared_ptr<const HeatmapFrame> cpu = cpu_frame(r);
  ASSERT_TRUE(cpu && cpu->complete) << what;
  EXPECT_EQ(gpu.id, id) << what;
  EXPECT_TRUE(gpu.complete) << what;
  EXPECT_EQ(gpu.stride, 1) << what;
  EXPECT_TRUE(same_heatmap_image(gpu.request.options, r.options)) << what;
  EXPECT_EQ(gpu.request.camera.position, r.camera.position) << what;
  EXPECT_EQ(gpu.image.metric, r.options.metric) << what;
  ASSERT_EQ(gpu.image.width, r.options.width) << what;
  ASSERT_EQ(gpu.image.height, r.options.height) << what;
  ASSERT_EQ(gpu.image.values.size(), cpu->image.values.size()) << what;
  ASSERT_EQ(gpu.pixels.size(), cpu->pixels.size()) << what;
  std::size_t wrong = 0, hits = 0;
  for (std::size_t i = 0; i < gpu.pixels.size(); ++i) {
    const PixelFigures &g = gpu.pixels[i], &c = cpu->pixels[i];
    const bool same = same_bits(gpu.image.values[i], cpu->image.values[i]) && same_bits(g.value, c.value) &&
                      g.nodes == c.nodes && g.prims == c.prims && g.instances == c.instances && g.prim == c.prim &&
                      same_bits(g.t, c.t) && g.shadow_rays == 0 && g.shadow_nodes == 0 && g.shadow_prims == 0 &&
                      g.shadowed == 0;
    if (!same && wrong++ == 0)
      ADD_FAILURE() << what << ": pixel " << i << " value " << g.value << " / " << c.value << ", nodes " << g.nodes
                    << " / " << c.nodes << ", prim " << g.prim << " / " << c.prim << ", t " << g.t << " / " << c.t;
    hits += g.prim != kInvalidId ? 1 : 0;
  }
  EXPECT_EQ(wrong, 0u) << what;
  EXPECT_GT(hits, 0u) << what;
  EXPECT_LT(hits, gpu.pixels.size()) << what;  // some background too
  const HeatmapSummary &gs = gpu.summary, &cs = cpu->summary;
  EXPECT_EQ(gs.rays, cs.rays) << what;
  EXPECT_EQ(gs.hits, cs.hits) << what;
  EXPECT_EQ(gs.max_nodes, cs.max_nodes) << what;
  EXPECT_EQ(gs.max_prims, cs.max_prims) << what;
  EXPECT_DOUBLE_EQ(gs.mean_nodes, cs.mean_nodes) << what;
  EXPECT_DOUBLE_EQ(gs.mean_prims, cs.mean_prims) << what;
  EXPECT_DOUBLE_EQ(gs.max_value, cs.max_value) << what;
  EXPECT_NEAR(gs.mean_value, cs.mean_value, 1e-9 * std::max(1.0, std::abs(cs.mean_value))) << what;
  EXPECT_EQ(gs.shadow_rays, 0u) << what;
}

TEST(GpuHeatmapFrame, EveryPixelAsTheCpuWorkerWhetherTheFrameIsNewOrWrittenOver) {
  const std::unique_ptr<GlContext> context = make_headless_context(8, 8, "osmesa");
  const Scene scene = load_scene("builtin:teapot-stadium?size=2000");
  auto built = std::make_shared<BuiltStructure>();
  built->accel = std::make_shared<const Bvh>(scene.triangles);
  const int w = 40, h = 29;
  const auto request = [&](HeatMetric m, const Camera& cam) {
    HeatmapRequest r;
    r.structure = built;
    r.camera = cam;
    r.options = HeatmapOptions{.metric = m, .width = w, .height = h};
    r.coarsest = 1;
    return r;
  };
  const Camera framed = frame_bounds(scene.bounds(), static_cast<float>(w) / h);
  const HeatmapRequest nodes = request(HeatMetric::nodes, framed);
  const HeatmapRequest shaded = request(HeatMetric::shaded, look_at({0.0f, 2.0f, 9.0f}, {0.0f, 6.0f, 0.0f}, 0.8f));
  const HeatmapRequest depth = request(HeatMetric::depth, framed);
  const HeatmapRequest cost = request(HeatMetric::cost, look_at({6.0f, 2.0f, -7.0f}, {0.0f, 5.0f, 0.0f}, 0.7f));

  {
    GpuHeatmap gui;
    std::shared_ptr<const HeatmapFrame> first = gui.trace(nodes, 1);
    ASSERT_TRUE(first);
    expect_frame_as_cpu(*first, nodes, 1, "a new frame");
    const HeatmapFrame* first_storage = first.get();
    std::shared_ptr<const HeatmapFrame> second = gui.trace(shaded, 2);  // the first still shown: a new one
    ASSERT_TRUE(second);
    EXPECT_NE(second.get(), first_storage);
    expect_frame_as_cpu(*second, shaded, 2, "a second new frame");
    EXPECT_GT(gui.last_finish_ms(), 0.0);
    EXPECT_GE(gui.last_finish_ms(), gui.last_readback_ms());

    first.reset();  // the window let go of it: written over by the next
    std::shared_ptr<const HeatmapFrame> third = gui.trace(depth, 3);
    EXPECT_EQ(third.get(), first_storage);
    expect_frame_as_cpu(*third, depth, 3, "the first frame written over");

    // Both still held: a third new frame, and neither of them changes.
    const std::vector<float> second_values = second->image.values;
    std::shared_ptr<const HeatmapFrame> fourth = gui.trace(cost, 4);
    EXPECT_NE(fourth.get(), second.get());
    EXPECT_NE(fourth.get(), third.get());
    expect_frame_as_cpu(*fourth, cost, 4, "a frame made while both others are held");
    EXPECT_EQ(second->id, 2u);
    EXPECT_EQ(second->image.values.size(), second_values.size());
    for (std::size_t i = 0; i < second_values.size(); ++i)
      ASSERT_TRUE(same_bits(second->image.values[i], second_values[i])) << "a shown frame changed at pixel " << i;

    second.reset();
    std::shared_ptr<const HeatmapFrame> fifth = gui.trace(nodes, 5);
    expect_frame_as_cpu(*fifth, nodes, 5, "the second frame written over");
  }  // GL objects go while the context is alive
}

}  // namespace gpu_heatmap_test
}  // namespace accelviz::test
