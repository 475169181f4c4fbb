// The progressive heatmap: coarse levels first, every pixel traced exactly
// once, the final level identical to core's render_metric, cancellation,
// and the worker always ending on its newest request.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <thread>

#include "core/accel/factory.h"
#include "core/query/camera.h"
#include "core/scene/load.h"
#include "ui/app/heatmap_worker.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_app_heatmap {

using namespace accelviz;
using namespace std::chrono_literals;

namespace {

std::shared_ptr<const BuiltStructure> teapot_bvh() {
  auto scene = std::make_shared<LoadedScene>();
  scene->spec = "builtin:teapot?size=500";
  scene->scene = load_scene(scene->spec);
  auto built = std::make_shared<BuiltStructure>();
  built->accel = build_accelerator("bvh", scene->scene.triangles, StructureOptions{});
  built->scene = scene;
  built->choice = StructureChoice{};
  return built;
}

HeatmapRequest request_for(const std::shared_ptr<const BuiltStructure>& b, int w, int h, HeatMetric m) {
  HeatmapRequest r;
  r.structure = b;
  r.camera = camera_from_spec("", b->scene->scene, static_cast<float>(w) / h);
  r.options.width = w;
  r.options.height = h;
  r.options.metric = m;
  r.options.threads = 2;
  return r;
}

bool same_value(float a, float b) {
  return (std::isnan(a) && std::isnan(b)) || a == b;
}

}  // namespace

TEST(AppHeatmap, LevelsRefineToExactlyWhatRenderComputes) {
  const auto built = teapot_bvh();
  // Sizes that are not multiples of 8, so partial blocks at the edges count.
  const int w = 53, h = 37;
  for (HeatMetric m : {HeatMetric::nodes, HeatMetric::depth}) {
    std::vector<std::shared_ptr<const HeatmapFrame>> frames;
    const HeatmapRequest r = request_for(built, w, h, m);
    ASSERT_TRUE(trace_progressive(
        r, 7, [] { return true; }, [&](auto f) { frames.push_back(f); }));
    ASSERT_EQ(frames.size(), 4u);
    EXPECT_EQ(frames[0]->stride, 8);
    EXPECT_EQ(frames[3]->stride, 1);
    EXPECT_TRUE(frames[3]->complete);
    EXPECT_FALSE(frames[2]->complete);
    EXPECT_EQ(frames[3]->id, 7u);

    // Each pixel traced once: the ray counts add up to the pixel count.
    const std::uint64_t coarse = static_cast<std::uint64_t>((w + 7) / 8) * ((h + 7) / 8);
    EXPECT_EQ(frames[0]->summary.rays, coarse);
    EXPECT_EQ(frames[3]->summary.rays, static_cast<std::uint64_t>(w) * h);

    // Coarse levels: every pixel shows its block's sample, in the image and
    // in its figures; a level holds the figures of its lattice points only.
    const HeatmapFrame& last = *frames[3];
    for (const auto& f : frames) {
      const int s = f->stride;
      ASSERT_EQ(f->lattice_width(), (w + s - 1) / s);
      ASSERT_EQ(f->pixels.size(), static_cast<std::size_t>(f->lattice_width()) * ((h + s - 1) / s)) << "stride " << s;
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
          const int bx = x / s * s, by = y / s * s;
          ASSERT_TRUE(same_value(f->image.at(x, y), f->image.at(bx, by)))
              << "stride " << s << " pixel " << x << "," << y;
          ASSERT_TRUE(same_value(f->image.at(bx, by), last.image.at(bx, by)))
              << "a sample keeps its exact value at every level";
          const PixelFigures &p = f->at(x, y), &q = last.at(bx, by);
          ASSERT_TRUE(same_value(p.value, f->image.at(x, y))) << "stride " << s << " pixel " << x << "," << y;
          ASSERT_TRUE(same_value(p.value, q.value) && p.nodes == q.nodes && p.prims == q.prims && p.prim == q.prim &&
                      same_value(p.t, q.t))
              << "stride " << s << " pixel " << x << "," << y << ": the figures of its block's sample";
        }
    }

    // The last level is core's heatmap, bit for bit.
    HeatmapFigures fig;
    const MetricImage expected = render_metric(*built->accel, r.camera, r.options, &fig);
    for (std::size_t i = 0; i < expected.values.size(); ++i)
      ASSERT_TRUE(same_value(frames[3]->image.values[i], expected.values[i])) << "pixel " << i;
    EXPECT_EQ(frames[3]->summary.hits, fig.hits);
    EXPECT_NEAR(frames[3]->summary.mean_value, fig.mean, 1e-9 * std::max(1.0, fig.mean));
    EXPECT_DOUBLE_EQ(frames[3]->summary.max_value, fig.max);
  }
}

TEST(AppHeatmap, PixelFiguresMatchASingleRay) {
  const auto built = teapot_bvh();
  const HeatmapRequest r = request_for(built, 40, 30, HeatMetric::prims);
  std::shared_ptr<const HeatmapFrame> last;
  trace_progressive(
      r, 1, [] { return true; }, [&](auto f) { last = f; });
  ASSERT_TRUE(last && last->complete);
  std::uint32_t max_nodes = 0;
  for (int y = 0; y < 30; y += 7)
    for (int x = 0; x < 40; x += 5) {
      RayStats stats;
      const Hit hit = built->accel->closest_hit(primary_ray(r.camera, x, y, 40, 30), {}, &stats);
      const PixelFigures& p = last->at(x, y);
      EXPECT_EQ(p.prim, hit.prim);
      EXPECT_EQ(p.nodes, stats.nodes_visited);
      EXPECT_EQ(p.prims, stats.prim_tests);
      EXPECT_EQ(p.value, static_cast<float>(stats.prim_tests));
    }
  for (const PixelFigures& p : last->pixels) max_nodes = std::max(max_nodes, p.nodes);
  EXPECT_EQ(last->summary.max_nodes, max_nodes);
}

TEST(AppHeatmap, StopsWhenToldTo) {
  const auto built = teapot_bvh();
  std::atomic<int> calls = 0;  // keep_going is asked from every tracing thread
  std::vector<int> strides;
  const bool done = trace_progressive(
      request_for(built, 64, 64, HeatMetric::nodes), 1, [&] { return ++calls < 12; },
      [&](auto f) { strides.push_back(f->stride); });
  EXPECT_FALSE(done);
  EXPECT_LT(strides.size(), 4u);
}

TEST(AppHeatmap, WorkerEndsOnTheNewestRequest) {
  const auto built = teapot_bvh();
  HeatmapWorker worker;
  std::uint64_t last = 0;
  for (int i = 0; i < 5; ++i) {
    HeatmapRequest r = request_for(built, 48 + i, 32, HeatMetric::nodes);
    last = worker.request(std::move(r));
  }
  const auto deadline = std::chrono::steady_clock::now() + 60s;
  std::shared_ptr<const HeatmapFrame> f;
  while (std::chrono::steady_clock::now() < deadline) {
    f = worker.latest();
    if (f && f->id == last && f->complete && !worker.busy()) break;
    std::this_thread::sleep_for(1ms);
  }
  ASSERT_TRUE(f);
  EXPECT_EQ(f->id, last);
  EXPECT_TRUE(f->complete);
  EXPECT_EQ(f->image.width, 52);
  EXPECT_EQ(worker.latest_request(), last);
}
}  // namespace unity_test_app_heatmap
