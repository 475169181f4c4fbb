// The "instances visited per ray" metric: RayStats::instances_visited is the
// two-level structure's own per-ray count (TwoLevelRayStats), it reaches the
// heatmap, and single-level structures leave it at 0.
#include <gtest/gtest.h>

#include "core/accel/bvh/bvh.h"
#include "core/accel/tlas/tlas.h"
#include "core/analysis/heatmap.h"
#include "core/query/camera.h"
#include "core/scene/load.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_heatmap_instances {

using namespace accelviz;

TEST(HeatmapInstances, NameParsesAndNeedsCounters) {
  const auto m = parse_metric("instances");
  ASSERT_TRUE(m.has_value());
  EXPECT_EQ(*m, HeatMetric::instances);
  EXPECT_EQ(metric_name(HeatMetric::instances), "instances");
  EXPECT_EQ(metric_label(HeatMetric::instances), "instances visited per ray");
  EXPECT_TRUE(metric_needs_stats(HeatMetric::instances));
}

TEST(HeatmapInstances, TwoLevelPixelsEqualTheTwoLevelCountsAndBvhIsZero) {
  const Scene scene = make_builtin("forest?size=2000&seed=3");
  ASSERT_GT(scene.instances.size(), 10u);
  const Tlas two(scene);
  const Bvh flat(scene.triangles);
  HeatmapOptions ho;
  ho.metric = HeatMetric::instances;
  ho.width = 48;
  ho.height = 36;
  ho.threads = 2;
  const Camera cam = camera_from_spec("", scene, 48.0f / 36.0f);
  HeatmapFigures fig;
  const MetricImage img = render_metric(two, cam, ho, &fig);
  ASSERT_EQ(img.values.size(), 48u * 36u);
  std::uint64_t hits = 0, hit_pixels_counted = 0, sum = 0, above_one = 0;
  for (int y = 0; y < ho.height; ++y)
    for (int x = 0; x < ho.width; ++x) {
      const Ray ray = primary_ray(cam, x, y, ho.width, ho.height);
      TwoLevelRayStats ts;
      const Hit h = two.closest_hit_two_level(ray, ho.query, &ts);
      // The fast path (no counters) finds the same hit.
      EXPECT_EQ(two.closest_hit(ray, ho.query).prim, h.prim);
      const float v = img.at(x, y);
      ASSERT_EQ(v, static_cast<float>(ts.instances_visited)) << "pixel " << x << "," << y;
      RayStats rs;
      two.closest_hit(ray, ho.query, &rs);
      EXPECT_EQ(rs.instances_visited, ts.instances_visited);
      if (h.valid()) {
        ++hits;
        hit_pixels_counted += v >= 1.0f;
      }
      above_one += v > 1.0f;
      sum += ts.instances_visited;
    }
  EXPECT_GT(hits, 100u);
  EXPECT_EQ(hit_pixels_counted, hits);  // a hit lies in some instance, so the ray entered one
  EXPECT_GT(above_one, 0u);             // overlapping tree boxes: some rays enter several
  EXPECT_NEAR(fig.mean, static_cast<double>(sum) / img.values.size(), 1e-9);

  // Single-level: no instances, the metric is 0 everywhere, hits or not.
  const MetricImage zero = render_metric(flat, cam, ho, &fig);
  for (float v : zero.values) ASSERT_EQ(v, 0.0f);
  EXPECT_GT(fig.hits, 100u);
  EXPECT_EQ(fig.max, 0.0);
}

}  // namespace unity_test_heatmap_instances
