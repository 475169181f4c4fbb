// The GPU heatmap path (shaders/trace_bvh.comp through GpuBvhTracer) counts
// exactly what the CPU's instrumented BVH traversal counts: per pixel the
// same nodes visited, box tests, primitive tests, culled and missed nodes,
// the same hit primitive and the bit-identical hit distance, on llvmpipe
// (through OSMesa and through EGL's software device), for small procedural
// scenes including degenerate ones and rays with exactly-zero direction
// components. Images are tiny: llvmpipe's
// compute is slow and this also runs under ASan.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <memory>
#include <sstream>
#include <string>

#include "core/accel/bvh/bvh.h"
#include "core/analysis/heatmap.h"
#include "core/query/camera.h"
#include "core/scene/load.h"
#include "ui/gl/headless.h"
#include "ui/render/gpu_trace.h"

namespace accelviz::test {
namespace gpu_trace_test {

/// Every test runs in both headless contexts (make_headless_context's
/// names): OSMesa, and EGL on a device (`render --device gpu --gl egl`, and
/// `auto` on a machine with a GPU): a GPU where there is one, else Mesa's
/// software device (llvmpipe), as in CI.
class GpuTrace : public ::testing::TestWithParam<const char*> {
 protected:
  void SetUp() override {
    context_ = make_headless_context(64, 48, GetParam());
    tracer_ = std::make_unique<GpuBvhTracer>();
  }
  void TearDown() override {
    tracer_.reset();  // GL objects go while their context is alive
    context_.reset();
  }

  /// Traces on both devices and expects every pixel to agree exactly.
  /// Returns the number of pixels that hit something (so callers can check
  /// the view is not trivially empty).
  std::uint64_t expect_equal(const Bvh& bvh, const Camera& cam, int w, int h, const QueryOptions& q,
                             const std::string& what) {
    tracer_->upload(bvh);
    const GpuTraceResult g = tracer_->trace(cam, w, h, q);
    EXPECT_EQ(g.stats.size(), static_cast<std::size_t>(w) * h);
    std::uint64_t mismatches = 0, hits = 0, max_nodes = 0;
    std::ostringstream first;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const std::size_t i = static_cast<std::size_t>(y) * w + x;
        RayStats s;
        const Hit c = bvh.closest_hit(primary_ray(cam, x, y, w, h), q, &s);
        const RayStats& gs = g.stats[i];
        const Hit& gh = g.hits[i];
        const bool same = gpu_pixel_matches(g, i, s, c);
        if (c.valid()) ++hits;
        max_nodes = std::max<std::uint64_t>(max_nodes, s.nodes_visited);
        if (!same && mismatches++ < 5)
          first << "\n  pixel " << x << "," << y << ": cpu nodes/boxes/prims/culled/missed " << s.nodes_visited << "/"
                << s.box_tests << "/" << s.prim_tests << "/" << s.nodes_culled << "/" << s.nodes_missed << " prim "
                << c.prim << " t " << c.t << "; gpu " << gs.nodes_visited << "/" << gs.box_tests << "/" << gs.prim_tests
                << "/" << gs.nodes_culled << "/" << gs.nodes_missed << " prim " << gh.prim << " t " << gh.t;
      }
    EXPECT_EQ(mismatches, 0u) << what << ": " << mismatches << " of " << w * h << " pixels differ" << first.str();
    EXPECT_GT(max_nodes, 1u) << what << ": the traversal never went below the root";
    return hits;
  }

  std::unique_ptr<GlContext> context_;
  std::unique_ptr<GpuBvhTracer> tracer_;
};

TEST_P(GpuTrace, TeapotStadiumMatchesTheCpuPerPixel) {
  const Scene scene = load_scene("builtin:teapot-stadium?size=3000");
  const Bvh bvh(scene.triangles);
  const int w = 64, h = 48;
  const Camera cam = frame_bounds(scene.bounds(), static_cast<float>(w) / h);
  const std::uint64_t hits = expect_equal(bvh, cam, w, h, QueryOptions{}, "teapot-stadium");
  EXPECT_GT(hits, 0u);
  EXPECT_LT(hits, static_cast<std::uint64_t>(w) * h);
}

TEST_P(GpuTrace, SoupMatchesForEveryTraversalChoice) {
  const Scene scene = load_scene("builtin:soup?size=1500");
  BvhOptions bo;
  bo.max_leaf_size = 2;
  const Bvh bvh(scene.triangles, bo);
  const int w = 48, h = 40;
  // Inside the cube of triangles, looking across it: many overlapping hits.
  const Camera cam = look_at({0.5f, 0.55f, 1.6f}, {0.5f, 0.5f, 0.5f}, 0.9f);
  QueryOptions q;
  EXPECT_GT(expect_equal(bvh, cam, w, h, q, "soup, watertight, front to back"), 0u);
  q.back_to_front = true;
  expect_equal(bvh, cam, w, h, q, "soup, back to front");
  q.back_to_front = false;
  q.ordered = false;
  expect_equal(bvh, cam, w, h, q, "soup, unordered");
  q.ordered = true;
  q.xray = true;
  expect_equal(bvh, cam, w, h, q, "soup, x-ray");
  q.xray = false;
  q.triangle_test = TriangleTest::moller_trumbore;
  expect_equal(bvh, cam, w, h, q, "soup, Moller-Trumbore");
}

// Axis-aligned view of degenerate geometry: the centre column and row of an
// odd-sized image have direction components of exactly 0 (inv_dir = ±inf,
// 0·inf = NaN in the slab test), the triangles all lie in z = 0 (flat boxes),
// and duplicated triangles make exact ties (the first found wins).
TEST_P(GpuTrace, DegenerateScenesAndZeroDirectionComponentsMatch) {
  const int w = 33, h = 25;
  const Camera front = look_at({0.0f, 0.0f, 3.0f}, {0.0f, 0.0f, 0.0f}, 1.2f);
  {
    const Scene scene = load_scene("builtin:flat-wall?size=400");
    const Bvh bvh(scene.triangles);
    const Camera cam = frame_bounds(scene.bounds(), static_cast<float>(w) / h);
    EXPECT_GT(expect_equal(bvh, cam, w, h, QueryOptions{}, "flat-wall, framed"), 0u);
    const glm::vec3 c = scene.bounds().center();
    EXPECT_GT(expect_equal(bvh, look_at(c + glm::vec3(0.0f, 0.0f, 2.0f), c, 1.2f), w, h, QueryOptions{},
                           "flat-wall, head-on along -z"),
              0u);
    // Grazing: the eye in the wall's plane, every ray parallel to it.
    expect_equal(bvh, look_at(c + glm::vec3(0.0f, -3.0f, 0.0f), c, 1.2f), w, h, QueryOptions{},
                 "flat-wall, eye in its plane");
  }
  {
    const Scene scene = load_scene("builtin:duplicates?size=24");
    const Bvh bvh(scene.triangles);
    const Camera cam = frame_bounds(scene.bounds(), static_cast<float>(w) / h);
    EXPECT_GT(expect_equal(bvh, cam, w, h, QueryOptions{}, "duplicates"), 0u);
  }
  {
    // Axis-aligned wall boxes seen straight from above: rays graze shared box
    // faces, where the slab test's exit padding (kSlabExitScale) decides.
    const Scene scene = load_scene("builtin:walls?size=600");
    const Bvh bvh(scene.triangles);
    const glm::vec3 c = scene.bounds().center();
    EXPECT_GT(expect_equal(bvh, look_at(c + glm::vec3(0.0f, 2.0f, 0.0f), c, 1.2f), 65, 49, QueryOptions{},
                           "walls, from above"),
              0u);
  }
  {
    const Scene scene = load_scene("builtin:same-centroid?size=200");
    const Bvh bvh(scene.triangles);
    expect_equal(bvh, front, w, h, QueryOptions{}, "same-centroid, along -z");
  }
}

// Hand-built triangles that take the watertight test's special cases, seen
// head-on by an odd-sized image whose centre row and column have direction
// components of exactly 0: two triangles sharing the edge y = 0 (edge
// functions of exactly 0, recomputed in double), a 1e-16-sized triangle on
// the centre ray (determinant below kWatertightLowRange: the whole test in
// double) and a 1e20-sized one behind everything (float overflow: double).
TEST_P(GpuTrace, WatertightSpecialCasesMatch) {
  std::vector<Triangle> tris = {
      {{-1.0f, 0.0f, 0.0f}, {1.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f}},
      {{-1.0f, 0.0f, 0.0f}, {0.0f, -1.0f, 0.0f}, {1.0f, 0.0f, 0.0f}},
      {{-1e-16f, -1e-16f, 0.5f}, {1e-16f, -1e-16f, 0.5f}, {0.0f, 1e-16f, 0.5f}},
      {{-1e20f, -1e20f, -5.0f}, {1e20f, -1e20f, -5.0f}, {0.0f, 1e20f, -5.0f}},
  };
  BvhOptions bo;
  bo.max_leaf_size = 1;
  bo.leaf_size_cap = 1;
  const Bvh bvh(tris, bo);
  const Camera cam = look_at({0.0f, 0.0f, 3.0f}, {0.0f, 0.0f, 0.0f}, 1.0f);
  const int w = 25, h = 19;
  EXPECT_EQ(expect_equal(bvh, cam, w, h, QueryOptions{}, "special cases"), static_cast<std::uint64_t>(w) * h);
  // The centre ray hits the tiny triangle, the centre row the shared edge.
  RayStats s;
  EXPECT_EQ(bvh.closest_hit(primary_ray(cam, w / 2, h / 2, w, h), QueryOptions{}, &s).prim, 2u);
  EXPECT_LT(bvh.closest_hit(primary_ray(cam, w / 2 + 3, h / 2, w, h), QueryOptions{}, &s).prim, 2u);
}

// A scene of 1e-30: the watertight test's float edge functions underflow to 0
// for every triangle and are redone in double (core/geometry/triangle.cpp
// step 5); the shader missed everything the CPU hit before it did the same.
TEST_P(GpuTrace, TinyScaleSceneIsHitAsOnTheCpu) {
  Scene scene = load_scene("builtin:teapot-stadium?size=400");
  for (Triangle& t : scene.triangles) {
    t.v0 *= 1e-30f;
    t.v1 *= 1e-30f;
    t.v2 *= 1e-30f;
  }
  const Bvh bvh(scene.triangles);
  const int w = 33, h = 25;
  const Camera cam = frame_bounds(scene.bounds(), static_cast<float>(w) / h);
  const std::uint64_t hits = expect_equal(bvh, cam, w, h, QueryOptions{}, "teapot-stadium at 1e-30");
  EXPECT_GT(hits, static_cast<std::uint64_t>(w) * h / 10);
}

// gpu_render_metric gives the MetricImage core's render_metric gives, so the
// colour map, legend and PNG are core's and identical.
TEST_P(GpuTrace, MetricImagesAndColourisedPicturesEqualTheCpus) {
  const Scene scene = load_scene("builtin:teapot?size=1000");
  const Bvh bvh(scene.triangles);
  tracer_->upload(bvh);
  HeatmapOptions ho;
  ho.width = 40;
  ho.height = 30;
  ho.threads = 1;
  ho.c_trav = 1.5f;
  const Camera cam = frame_bounds(scene.bounds(), 40.0f / 30.0f);
  for (HeatMetric m : {HeatMetric::nodes, HeatMetric::prims, HeatMetric::cost, HeatMetric::depth, HeatMetric::shaded}) {
    ho.metric = m;
    HeatmapFigures fc, fg;
    const MetricImage cpu = render_metric(bvh, cam, ho, &fc);
    const MetricImage gpu = gpu_render_metric(*tracer_, cam, ho, &fg);
    ASSERT_EQ(cpu.values.size(), gpu.values.size());
    std::size_t differ = 0;
    for (std::size_t i = 0; i < cpu.values.size(); ++i)
      if (std::bit_cast<std::uint32_t>(cpu.values[i]) != std::bit_cast<std::uint32_t>(gpu.values[i]) &&
          !(std::isnan(cpu.values[i]) && std::isnan(gpu.values[i])))
        ++differ;
    EXPECT_EQ(differ, 0u) << metric_name(m);
    EXPECT_EQ(fc.hits, fg.hits) << metric_name(m);
    EXPECT_GT(fg.hits, 0u);
    EXPECT_DOUBLE_EQ(fc.mean, fg.mean) << metric_name(m);
    EXPECT_DOUBLE_EQ(fc.max, fg.max) << metric_name(m);
    const RgbImage a = colorize(cpu, ColorizeOptions{}), b = colorize(gpu, ColorizeOptions{});
    EXPECT_EQ(a.pixels, b.pixels) << metric_name(m);
  }
}

// The GUI spreads an image over frames in row bands (begin, trace_rows,
// result): after each band exactly the rows traced so far hold the one-shot
// trace's figures, bit for bit, and every later row reads untraced (rows
// an earlier trace or a band of another view wrote included). Band sizes are uneven and the height is not
// a multiple of the 8-row work group; a second begin() (the view changed
// mid-trace) starts from an untraced image again.
TEST_P(GpuTrace, BandedTraceEqualsTheOneShotTraceBandByBand) {
  const Scene scene = load_scene("builtin:teapot-stadium?size=2000");
  const Bvh bvh(scene.triangles);
  tracer_->upload(bvh);
  const int w = 40, h = 29;
  const Camera cam = frame_bounds(scene.bounds(), static_cast<float>(w) / h);
  const GpuTraceResult whole = tracer_->trace(cam, w, h, QueryOptions{});
  std::uint64_t whole_hits = 0;
  for (const Hit& hit : whole.hits) whole_hits += hit.valid() ? 1 : 0;
  ASSERT_GT(whole_hits, 0u);

  // A restart mid-trace: one band of another view, then the real one.
  tracer_->begin(look_at({0.0f, 5.0f, 9.0f}, {0.0f, 0.0f, 0.0f}, 0.8f), w, h, QueryOptions{});
  tracer_->trace_rows(20);  // rows 5..19 below must read untraced again
  tracer_->begin(cam, w, h, QueryOptions{});
  EXPECT_EQ(tracer_->rows_done(), 0);
  EXPECT_EQ(tracer_->rows_total(), h);
  int expect_done = 0, bands = 0;
  double band_ms = 0.0;
  for (const int rows : {5, 8, 1, 13, 100}) {
    ASSERT_FALSE(tracer_->finished());
    band_ms += tracer_->trace_rows(rows);
    ++bands;
    expect_done = std::min(h, expect_done + rows);
    ASSERT_EQ(tracer_->rows_done(), expect_done);
    const GpuTraceResult r = tracer_->result();
    ASSERT_EQ(r.stats.size(), whole.stats.size());
    std::size_t wrong_traced = 0, wrong_untraced = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const std::size_t i = static_cast<std::size_t>(y) * w + x;
        const RayStats &a = r.stats[i], &b = whole.stats[i];
        if (y < expect_done) {
          wrong_traced += gpu_pixel_matches(r, i, b, whole.hits[i]) ? 0 : 1;
        } else {
          const bool untraced = a.nodes_visited == GpuBvhTracer::kUntraced && a.box_tests == GpuBvhTracer::kUntraced &&
                                a.prim_tests == GpuBvhTracer::kUntraced && !r.hits[i].valid();
          wrong_untraced += untraced ? 0 : 1;
        }
      }
    EXPECT_EQ(wrong_traced, 0u) << "band " << bands << ": rows [0, " << expect_done << ") differ from one shot";
    EXPECT_EQ(wrong_untraced, 0u) << "band " << bands << ": rows [" << expect_done << ", " << h
                                  << ") do not read untraced";
    EXPECT_DOUBLE_EQ(r.trace_ms, band_ms);
    if (tracer_->finished()) break;
  }
  EXPECT_TRUE(tracer_->finished());
  EXPECT_EQ(bands, 5);                     // 5 + 8 + 1 + 13 = 27 rows, then the last 2
  EXPECT_EQ(tracer_->trace_rows(8), 0.0);  // nothing left: no dispatch
  EXPECT_THROW(tracer_->trace_rows(0), std::invalid_argument);
  GpuBvhTracer fresh;
  EXPECT_THROW(fresh.trace_rows(8), std::logic_error);
  EXPECT_THROW(fresh.result(), std::logic_error);
}

TEST_P(GpuTrace, RejectsBadInputAndNamesUnsupportedStructures) {
  EXPECT_THROW(tracer_->trace(Camera{}, 8, 8, QueryOptions{}), std::logic_error);  // nothing uploaded
  const Scene scene = load_scene("builtin:soup?size=10");
  const Bvh bvh(scene.triangles);
  tracer_->upload(bvh);
  EXPECT_THROW(tracer_->trace(Camera{}, 0, 8, QueryOptions{}), std::invalid_argument);
  EXPECT_TRUE(gpu_trace_unsupported("bvh").empty());
  EXPECT_EQ(gpu_trace_unsupported("grid"), "only the bvh structure is traced on the GPU");
  // An empty BVH: every ray misses, nothing is counted but the (absent) root.
  const Bvh empty(std::span<const Triangle>{});
  tracer_->upload(empty);
  const GpuTraceResult r = tracer_->trace(Camera{}, 9, 7, QueryOptions{});
  for (std::size_t i = 0; i < r.hits.size(); ++i) {
    EXPECT_FALSE(r.hits[i].valid());
    EXPECT_EQ(r.stats[i].nodes_visited, 0u);
    EXPECT_EQ(r.stats[i].box_tests, 0u);
  }
}

INSTANTIATE_TEST_SUITE_P(Context, GpuTrace, ::testing::Values("osmesa", "egl"),
                         [](const ::testing::TestParamInfo<const char*>& info) { return std::string(info.param); });

}  // namespace gpu_trace_test
}  // namespace accelviz::test
