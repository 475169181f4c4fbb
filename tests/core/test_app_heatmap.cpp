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
#include "tests/support/refusing_accelerator.h"
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

/// Two frames show the same: their levels, images and every figure of every
/// lattice point.
void expect_same_frame(const HeatmapFrame& a, const HeatmapFrame& b) {
  EXPECT_EQ(a.id, b.id);
  EXPECT_EQ(a.stride, b.stride);
  EXPECT_EQ(a.complete, b.complete);
  EXPECT_EQ(a.summary.rays, b.summary.rays);
  EXPECT_EQ(a.summary.hits, b.summary.hits);
  EXPECT_EQ(a.summary.max_nodes, b.summary.max_nodes);
  EXPECT_EQ(a.image.width, b.image.width);
  EXPECT_EQ(a.image.height, b.image.height);
  EXPECT_EQ(a.image.metric, b.image.metric);
  ASSERT_EQ(a.image.values.size(), b.image.values.size());
  for (std::size_t i = 0; i < a.image.values.size(); ++i)
    ASSERT_TRUE(same_value(a.image.values[i], b.image.values[i])) << "image value " << i << ", stride " << a.stride;
  ASSERT_EQ(a.pixels.size(), b.pixels.size());
  for (std::size_t i = 0; i < a.pixels.size(); ++i) {
    const PixelFigures &p = a.pixels[i], &q = b.pixels[i];
    ASSERT_TRUE(same_value(p.value, q.value) && p.nodes == q.nodes && p.prims == q.prims &&
                p.instances == q.instances && p.prim == q.prim && same_value(p.t, q.t) &&
                p.shadow_rays == q.shadow_rays && p.shadow_nodes == q.shadow_nodes &&
                p.shadow_prims == q.shadow_prims && p.shadowed == q.shadowed)
        << "pixel " << i << ", stride " << a.stride;
  }
}

}  // namespace

TEST(AppHeatmap, LevelsRefineToExactlyWhatRenderComputes) {
  const auto built = teapot_bvh();
  // Sizes that are not multiples of 8, so partial blocks at the edges count.
  const int w = 53, h = 37;
  for (HeatMetric m : {HeatMetric::nodes, HeatMetric::depth}) {
    std::vector<std::shared_ptr<const HeatmapFrame>> frames;
    const HeatmapRequest r = request_for(built, w, h, m);
    std::atomic<std::uint64_t> traced{0};  // the status line's percentage: every pixel's ray once
    std::vector<std::uint64_t> traced_at_level;
    ASSERT_TRUE(trace_progressive(
        r, 7, [] { return true; },
        [&](auto f) {
          frames.push_back(f);
          traced_at_level.push_back(traced.load());
        },
        nullptr, &traced));
    EXPECT_EQ(traced.load(), static_cast<std::uint64_t>(w) * h);
    ASSERT_EQ(traced_at_level.size(), 4u);
    EXPECT_EQ(traced_at_level[0], static_cast<std::uint64_t>((w + 7) / 8) * ((h + 7) / 8));
    EXPECT_LT(traced_at_level[2], traced_at_level[3]);
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

TEST(AppHeatmap, PooledFramesAreWrittenWhollyAndOnlyWhenNoOneHoldsThem) {
  const auto built = teapot_bvh();
  const int w = 53, h = 37;
  HeatmapRequest first = request_for(built, w, h, HeatMetric::nodes);
  first.shadow_lights.push_back(Light{});  // the shadow figures too
  first.shadow_lights.back().position = {0.0f, 100.0f, 0.0f};
  // Another camera, metric and no lights: every figure of a reused frame's
  // stale content differs somewhere from what the second job writes.
  HeatmapRequest second = request_for(built, w, h, HeatMetric::depth);
  second.camera.position += 0.3f * second.camera.up;

  HeatmapFramePool pool;
  std::vector<std::shared_ptr<const HeatmapFrame>> a;
  ASSERT_TRUE(trace_progressive(
      first, 1, [] { return true; }, [&](auto f) { a.push_back(f); }, &pool));
  ASSERT_EQ(a.size(), 4u);
  EXPECT_EQ(pool.size(), 4u) << "one frame per spacing";
  const HeatmapFrame* first_job[4] = {a[0].get(), a[1].get(), a[2].get(), a[3].get()};

  // The shown frame (the last level) is held: the next job must not write
  // over it; the coarser ones are let go and written over.
  const std::shared_ptr<const HeatmapFrame> shown = a[3];
  a.clear();
  std::vector<std::shared_ptr<const HeatmapFrame>> b, want;
  ASSERT_TRUE(trace_progressive(
      second, 2, [] { return true; }, [&](auto f) { b.push_back(f); }, &pool));
  ASSERT_TRUE(trace_progressive(
      second, 2, [] { return true; }, [&](auto f) { want.push_back(f); }));
  ASSERT_EQ(b.size(), 4u);
  ASSERT_EQ(want.size(), 4u);
  for (int k = 0; k < 3; ++k) EXPECT_EQ(b[k].get(), first_job[k]) << "level " << k << " reuses its frame";
  EXPECT_NE(b[3].get(), first_job[3]) << "a held frame is never written over";
  EXPECT_EQ(shown->id, 1u);
  EXPECT_EQ(shown->request.options.metric, HeatMetric::nodes);
  EXPECT_EQ(pool.size(), 5u) << "a second frame of spacing 1, kept";
  for (int k = 0; k < 4; ++k) {
    SCOPED_TRACE("level " + std::to_string(k));
    expect_same_frame(*b[k], *want[k]);  // nothing stale left in a reused frame
    EXPECT_EQ(b[k]->request.options.metric, HeatMetric::depth);
  }
  // The second job's frames held too: a third job makes new ones, kept up to
  // two per spacing; its spacing-1 frame is not kept (the first two are).
  std::vector<std::shared_ptr<const HeatmapFrame>> c;
  ASSERT_TRUE(trace_progressive(
      first, 3, [] { return true; }, [&](auto f) { c.push_back(f); }, &pool));
  ASSERT_EQ(c.size(), 4u);
  EXPECT_NE(c[3].get(), shown.get());
  EXPECT_NE(c[3].get(), b[3].get());
  EXPECT_EQ(pool.size(), 8u);
  EXPECT_EQ(c[3].use_count(), 1) << "not kept by the pool";
  EXPECT_EQ(c[0].use_count(), 2) << "kept by the pool";
  // A frame no one holds lets go of its request, and so of the structure.
  const HeatmapFrame* idle = c[0].get();
  c.clear();
  b.clear();
  pool.take(16);  // any take looks at every kept frame
  EXPECT_EQ(idle->request.structure, nullptr);
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

using accelviz::testing::RefusingAccelerator;

// A query that throws on the worker thread ended the program (std::terminate): the worker keeps the
// failure and its message for the status line, publishes no frame for that job, and goes on to
// trace the next request.
TEST(AppHeatmap, AWorkerWhoseStructureThrowsSaysWhyAndGoesOn) {
  const auto good = teapot_bvh();
  auto refusing = std::make_shared<BuiltStructure>(*good);
  refusing->accel = std::make_shared<RefusingAccelerator>();
  HeatmapWorker worker;
  const std::uint64_t failed = worker.request(request_for(refusing, 32, 24, HeatMetric::nodes));
  const auto deadline = std::chrono::steady_clock::now() + 60s;
  while (worker.failure().first != failed && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(1ms);
  EXPECT_EQ(worker.failure().first, failed);
  EXPECT_EQ(worker.failure().second, "refusing: cannot trace this ray");
  EXPECT_FALSE(worker.latest() && worker.latest()->complete);
  const std::uint64_t next = worker.request(request_for(good, 32, 24, HeatMetric::nodes));
  std::shared_ptr<const HeatmapFrame> f;
  while (std::chrono::steady_clock::now() < deadline) {
    f = worker.latest();
    if (f && f->id == next && f->complete && !worker.busy()) break;
    std::this_thread::sleep_for(1ms);
  }
  ASSERT_TRUE(f);
  EXPECT_EQ(f->id, next);
  EXPECT_EQ(worker.failure().first, failed) << "the failure stays the last one's until another job fails";
}
}  // namespace unity_test_app_heatmap
