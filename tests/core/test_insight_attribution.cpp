// Insight: per-node visit attribution (hot nodes, pixels of a node, what a
// region touched) and the A/B difference images, on hand-computed cases.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <limits>
#include <vector>

#include "core/accel/bvh/bvh.h"
#include "core/analysis/insight/compare_images.h"
#include "core/analysis/insight/visit_attribution.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_insight_attribution {

using namespace accelviz;

namespace {

// Two triangles side by side in the plane z = 0: A over x in [0,1], B over x in [2,3].
std::vector<Triangle> side_by_side() {
  return {Triangle{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, Triangle{{2, 0, 0}, {3, 0, 0}, {2, 1, 0}}};
}

BvhOptions one_per_leaf() {
  BvhOptions o;
  o.max_leaf_size = 1;
  o.leaf_size_cap = 1;
  o.compute_epo = false;
  return o;
}

Ray down(float x, float y) {
  return Ray({x, y, 5.0f}, {0.0f, 0.0f, -1.0f});
}

// 2x2 "image": (0,0) hits A, (1,0) passes between them, (0,1) hits B, (1,1) misses the root.
std::vector<Ray> four_rays() {
  return {down(0.25f, 0.25f), down(1.5f, 0.5f), down(2.25f, 0.25f), down(5.0f, 5.0f)};
}

std::uint32_t leaf_with_hi_x(const Bvh& bvh, float hi_x) {
  for (std::uint32_t i = 0; i < bvh.nodes().size(); ++i)
    if (bvh.nodes()[i].is_leaf() && bvh.nodes()[i].bounds.hi.x == hi_x) return i;
  return 999;
}

}  // namespace

TEST(InsightAttribution, RecordsNodesAndPrimsPerPixel) {
  const auto tris = side_by_side();
  const Bvh bvh(tris, one_per_leaf());
  ASSERT_EQ(bvh.nodes().size(), 3u);
  const std::uint32_t leaf_a = leaf_with_hi_x(bvh, 1.0f), leaf_b = leaf_with_hi_x(bvh, 3.0f);
  ASSERT_NE(leaf_a, leaf_b);
  const auto rays = four_rays();
  const VisitRecord rec = record_visits(bvh, rays, 2, 2, QueryOptions{}, 1);
  EXPECT_EQ(std::vector<std::uint32_t>(rec.nodes_of(0).begin(), rec.nodes_of(0).end()),
            (std::vector<std::uint32_t>{0, leaf_a}));
  EXPECT_EQ(std::vector<std::uint32_t>(rec.nodes_of(1).begin(), rec.nodes_of(1).end()), std::vector<std::uint32_t>{0});
  EXPECT_EQ(std::vector<std::uint32_t>(rec.nodes_of(2).begin(), rec.nodes_of(2).end()),
            (std::vector<std::uint32_t>{0, leaf_b}));
  EXPECT_TRUE(rec.nodes_of(3).empty());
  EXPECT_EQ(std::vector<std::uint32_t>(rec.prims_of(0).begin(), rec.prims_of(0).end()), std::vector<std::uint32_t>{0});
  EXPECT_TRUE(rec.prims_of(1).empty());
  EXPECT_EQ(std::vector<std::uint32_t>(rec.prims_of(2).begin(), rec.prims_of(2).end()), std::vector<std::uint32_t>{1});
  EXPECT_EQ(rec.hit_prim[0], 0u);
  EXPECT_EQ(rec.hit_prim[1], VisitRecord::kNoHitPrim);
  EXPECT_EQ(rec.hit_prim[2], 1u);
  for (std::size_t p = 0; p < 4; ++p) EXPECT_EQ(rec.stats[p].nodes_visited, rec.nodes_of(p).size()) << p;
  // The same with all threads gives the same record.
  const VisitRecord par = record_visits(bvh, rays, 2, 2, QueryOptions{}, 0);
  EXPECT_EQ(par.nodes, rec.nodes);
  EXPECT_EQ(par.prims, rec.prims);
}

TEST(InsightAttribution, CountsHotNodesPixelsAndRegions) {
  const auto tris = side_by_side();
  const Bvh bvh(tris, one_per_leaf());
  const std::uint32_t leaf_a = leaf_with_hi_x(bvh, 1.0f), leaf_b = leaf_with_hi_x(bvh, 3.0f);
  const auto rays = four_rays();
  const VisitRecord rec = record_visits(bvh, rays, 2, 2, QueryOptions{}, 1);

  const auto counts = node_visit_counts(rec, bvh.nodes().size());
  EXPECT_EQ(counts[0], 3u);
  EXPECT_EQ(counts[leaf_a], 1u);
  EXPECT_EQ(counts[leaf_b], 1u);

  const auto hot = top_hot_nodes(counts, 2);
  ASSERT_EQ(hot.size(), 2u);
  EXPECT_EQ(hot[0].node, 0u);
  EXPECT_EQ(hot[0].visits, 3u);
  EXPECT_EQ(hot[1].node, std::min(leaf_a, leaf_b));  // tie: lower id first
  EXPECT_EQ(top_hot_nodes(counts, 10).size(), 3u);
  const std::vector<std::uint64_t> none{0, 0};
  EXPECT_TRUE(top_hot_nodes(none, 5).empty());

  EXPECT_EQ(pixels_visiting(rec, leaf_a), (std::vector<std::uint8_t>{1, 0, 0, 0}));
  EXPECT_EQ(pixels_visiting(rec, leaf_b), (std::vector<std::uint8_t>{0, 0, 1, 0}));
  EXPECT_EQ(pixels_visiting(rec, 0), (std::vector<std::uint8_t>{1, 1, 1, 0}));

  const RegionTouch top_row = region_touch(rec, 0, 0, 2, 1);
  EXPECT_EQ(top_row.rays, 2u);
  EXPECT_EQ(top_row.nodes, (std::vector<std::uint32_t>{0, leaf_a}));
  EXPECT_EQ(top_row.prims, std::vector<std::uint32_t>{0});
  EXPECT_EQ(top_row.hit_prims, std::vector<std::uint32_t>{0});
  const RegionTouch all = region_touch(rec, -5, -5, 100, 100);  // clamped to the image
  EXPECT_EQ(all.rays, 4u);
  EXPECT_EQ(all.nodes, (std::vector<std::uint32_t>{0, 1, 2}));
  EXPECT_EQ(all.prims, (std::vector<std::uint32_t>{0, 1}));
  const RegionTouch empty = region_touch(rec, 1, 1, 1, 2);
  EXPECT_EQ(empty.rays, 0u);
  EXPECT_TRUE(empty.nodes.empty());
}

TEST(InsightAttribution, RejectsMismatchedSizes) {
  const auto tris = side_by_side();
  const Bvh bvh(tris, one_per_leaf());
  const auto rays = four_rays();
  EXPECT_THROW(record_visits(bvh, rays, 3, 2, QueryOptions{}), std::invalid_argument);
  EXPECT_THROW(record_visits(bvh, rays, 0, 0, QueryOptions{}), std::invalid_argument);
}

TEST(InsightCompare, DifferenceTotalsAndColours) {
  MetricImage a, b;
  a.width = b.width = 3;
  a.height = b.height = 1;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  a.values = {1.0f, 3.0f, 2.0f};
  b.values = {2.0f, 1.0f, nan};
  ABFigures f;
  const MetricImage d = difference_image(a, b, &f);
  EXPECT_FLOAT_EQ(d.values[0], 1.0f);
  EXPECT_FLOAT_EQ(d.values[1], -2.0f);
  EXPECT_TRUE(std::isnan(d.values[2]));
  EXPECT_EQ(f.pixels, 2u);
  EXPECT_DOUBLE_EQ(f.total_a, 4.0);
  EXPECT_DOUBLE_EQ(f.total_b, 3.0);
  EXPECT_DOUBLE_EQ(f.mean_a, 2.0);
  EXPECT_DOUBLE_EQ(f.max_abs_diff, 2.0);
  EXPECT_EQ(f.b_cheaper, 1u);
  EXPECT_EQ(f.b_dearer, 1u);
  EXPECT_FLOAT_EQ(locked_scale_max(a, b, 0.0f), 3.0f);
  EXPECT_FLOAT_EQ(locked_scale_max(a, b, 7.0f), 7.0f);

  // Diverging: B dearer is red (r > b), B cheaper blue, no change near white.
  const glm::vec3 bg(0.3f);
  const glm::u8vec3 up = difference_color(2.0f, 2.0f, bg), dn = difference_color(-2.0f, 2.0f, bg),
                    zero = difference_color(0.0f, 2.0f, bg);
  EXPECT_GT(up.x, up.z);
  EXPECT_GT(dn.z, dn.x);
  EXPECT_GT(std::min({zero.x, zero.y, zero.z}), 200);
  EXPECT_EQ(difference_color(nan, 2.0f, bg), to_rgb8(bg));

  const RgbImage img = colorize_difference(d, 0.0f);
  EXPECT_EQ(img.width, 3);
  EXPECT_GT(img.height, 1);     // legend below
  EXPECT_EQ(img.at(1, 0), dn);  // auto scale = 2
  EXPECT_EQ(colorize_difference(d, 0.0f, LegendPlacement::none).height, 1);

  MetricImage c = a;
  c.width = 1;
  c.height = 3;
  EXPECT_THROW(difference_image(a, c), std::invalid_argument);
}

TEST(InsightCompare, TimedClosestHitsAreTheTracedHitsAndTheirCount) {
  // What a choice costs in time (render --compare, the GUI's A/B): the timed
  // pass's hits are the closest hits, counted; a cancel stops it.
  const std::vector<Triangle> tris = side_by_side();
  const Bvh bvh(tris, one_per_leaf());
  const std::vector<Ray> rays = four_rays();
  const TimedClosestHits t = time_closest_hits(bvh, rays, QueryOptions{}, 1, 3);
  ASSERT_EQ(t.hits.size(), 4u);
  EXPECT_EQ(t.hits[0].prim, 0u);
  EXPECT_FALSE(t.hits[1].valid());
  EXPECT_EQ(t.hits[2].prim, 1u);
  EXPECT_FALSE(t.hits[3].valid());
  EXPECT_EQ(t.hit_count, 2u);
  EXPECT_GE(t.trace_ms, 0.0);
  EXPECT_THROW(time_closest_hits(bvh, rays, QueryOptions{}, 1, 3, [](double) { return false; }), BuildCancelled);
  // Four rays take microseconds: more passes than asked (up to 64) until 30 ms, so that the median
  // is not one pass that other work slowed (three passes read up to 10x in the GUI's A/B dump).
  int passes = 0;
  std::vector<double> fractions;
  time_closest_hits(bvh, rays, QueryOptions{}, 1, 3, [&](double f) {
    ++passes;
    fractions.push_back(f);
    return true;
  });
  EXPECT_GT(passes, 3);
  EXPECT_LE(passes, 64);
  EXPECT_EQ(fractions.back(), 1.0);
}

TEST(InsightCompare, HitsChangedCountsAHitLostGainedOrMovedToAnotherTriangle) {
  Hit a0, a1, a2, a3, b0, b1, b2, b3;
  a0.prim = b0.prim = 4;  // same triangle (another t does not count)
  b0.t = 2.0f;
  a1.prim = 1;  // lost
  b2.prim = 2;  // gained
  a3.prim = 3;  // moved
  b3.prim = 5;
  const std::vector<Hit> a = {a0, a1, a2, a3, Hit{}}, b = {b0, b1, b2, b3, Hit{}};
  EXPECT_EQ(hits_changed(a, b), 3u);
  EXPECT_EQ(hits_changed(a, a), 0u);
  EXPECT_THROW(hits_changed(a, std::vector<Hit>(2)), std::invalid_argument);
}

}  // namespace unity_test_insight_attribution
