// Insight: predicted (SAH, surface-area hit probabilities) vs measured cost
// on a hand-computed tree, and the traversal counters (culled, x-ray,
// child order, any-hit leaves skipped).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/accel/bvh/bvh.h"
#include "core/analysis/insight/predicted_cost.h"
#include "core/analysis/insight/traversal_modes.h"
#include "core/analysis/insight/visit_attribution.h"
#include "core/analysis/sah.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_insight_predicted {

using namespace accelviz;

namespace {

BvhOptions one_per_leaf(float c_isect = 1.0f, bool epo = false) {
  BvhOptions o;
  o.max_leaf_size = 1;
  o.leaf_size_cap = 1;
  o.cost_intersect = c_isect;
  o.compute_epo = epo;
  return o;
}

Ray down(float x, float y) {
  return Ray({x, y, 5.0f}, {0.0f, 0.0f, -1.0f});
}

}  // namespace

TEST(InsightPredicted, HitProbabilitiesAreAreaRatios) {
  // Root box [0,3]x[0,1]x{0}: half area 3·1 = 3; each leaf [.,.+1]x[0,1]: 1.
  const std::vector<Triangle> tris{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{2, 0, 0}, {3, 0, 0}, {2, 1, 0}}};
  const Bvh bvh(tris, one_per_leaf());
  const auto p = bvh_hit_probabilities(bvh.nodes());
  ASSERT_EQ(p.size(), 3u);
  EXPECT_DOUBLE_EQ(p[0], 1.0);
  EXPECT_NEAR(p[1], 1.0 / 3.0, 1e-6);
  EXPECT_NEAR(p[2], 1.0 / 3.0, 1e-6);
  EXPECT_TRUE(bvh_hit_probabilities({}).empty());
}

TEST(InsightPredicted, MeasuredCostUsesTheSahTerms) {
  const std::vector<Triangle> tris{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{2, 0, 0}, {3, 0, 0}, {2, 1, 0}}};
  for (const float c_isect : {1.0f, 2.0f}) {
    const Bvh bvh(tris, one_per_leaf(c_isect, /*epo=*/true));
    const std::vector<Ray> rays{down(0.25f, 0.25f), down(1.5f, 0.5f), down(2.25f, 0.25f), down(5.0f, 5.0f)};
    const VisitRecord rec = record_visits(bvh, rays, 2, 2, QueryOptions{}, 1);
    const CostComparison c = compare_predicted_measured(bvh, rec);
    // SAH = C_trav·1 + C_isect·(1·1/3 + 1·1/3).
    EXPECT_NEAR(c.sah, 1.0 + c_isect * 2.0 / 3.0, 1e-6);
    EXPECT_NEAR(c.sah, bvh_sah_cost(bvh.nodes(), 1.0, c_isect), 1e-9);
    EXPECT_TRUE(std::isfinite(c.epo));
    EXPECT_EQ(c.rays, 4u);
    EXPECT_EQ(c.root_rays, 3u);  // the fourth misses the root box
    EXPECT_NEAR(c.nodes_per_ray, 5.0 / 3.0, 1e-12);
    EXPECT_NEAR(c.inner_per_ray, 1.0, 1e-12);
    EXPECT_NEAR(c.prims_per_ray, 2.0 / 3.0, 1e-12);
    EXPECT_NEAR(c.cost_per_ray, 1.0 + c_isect * 2.0 / 3.0, 1e-12);
    EXPECT_NEAR(c.ratio, 1.0, 1e-6);  // this view samples the leaves exactly in proportion to their areas
    const auto f = measured_entry_fractions(rec, bvh.nodes().size());
    EXPECT_DOUBLE_EQ(f[0], 1.0);
    EXPECT_NEAR(f[1], 1.0 / 3.0, 1e-12);
    EXPECT_NEAR(f[2], 1.0 / 3.0, 1e-12);
  }
  const Bvh no_epo(tris, one_per_leaf());
  const std::vector<Ray> rays{down(0.25f, 0.25f)};
  EXPECT_TRUE(std::isnan(compare_predicted_measured(no_epo, record_visits(no_epo, rays, 1, 1, {}, 1)).epo));
}

namespace {

// A in z = 0 in front of B in z = -1, same footprint; rays come from z = 5 looking down -z.
std::vector<Triangle> stacked() {
  return {Triangle{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, Triangle{{0, 0, -1}, {1, 0, -1}, {0, 1, -1}}};
}

}  // namespace

TEST(InsightTraversal, CulledXrayOrderAndAnyHitCounters) {
  for (const bool wide : {true, false}) {
    BvhOptions o = one_per_leaf();
    o.wide_traversal = wide;
    const Bvh bvh(stacked(), o);
    const Ray ray = down(0.25f, 0.25f);
    const auto run = [&](TraversalMode m) {
      RayStats s;
      const QueryOptions q = query_for_mode(QueryOptions{}, m);
      if (m == TraversalMode::any_hit) {
        EXPECT_TRUE(bvh.any_hit(ray, q, &s));
      } else {
        const Hit h = bvh.closest_hit(ray, q, &s);
        EXPECT_EQ(h.prim, 0u) << mode_name(m);  // every mode finds the front triangle
        EXPECT_FLOAT_EQ(h.t, 5.0f);
        // The counter-free call agrees on the hit.
        EXPECT_EQ(bvh.closest_hit(ray, q).prim, 0u) << mode_name(m);
      }
      return s;
    };
    // Front-to-back: root, A (hit at t = 5), then B (entry t = 6) culled.
    const RayStats f2b = run(TraversalMode::front_to_back);
    EXPECT_EQ(f2b.nodes_visited, 2u);
    EXPECT_EQ(f2b.nodes_culled, 1u);
    EXPECT_EQ(f2b.prim_tests, 1u);
    EXPECT_EQ(f2b.nodes_missed, 0u);
    // Back-to-front: root, B (hit at t = 6), A (entry 5 < 6) entered and tested too.
    const RayStats b2f = run(TraversalMode::back_to_front);
    EXPECT_EQ(b2f.nodes_visited, 3u);
    EXPECT_EQ(b2f.nodes_culled, 0u);
    EXPECT_EQ(b2f.prim_tests, 2u);
    // Unordered: left child first, which is B (the lower z bucket).
    const RayStats un = run(TraversalMode::unordered);
    EXPECT_EQ(un.nodes_visited, 3u);
    EXPECT_EQ(un.prim_tests, 2u);
    // X-ray: nothing culled, the full traversal.
    const RayStats xr = run(TraversalMode::xray);
    EXPECT_EQ(xr.nodes_visited, 3u);
    EXPECT_EQ(xr.nodes_culled, 0u);
    EXPECT_EQ(xr.prim_tests, 2u);
    // Any-hit stops in A; B's leaf, crossed by the ray, was never reached.
    const RayStats any = run(TraversalMode::any_hit);
    EXPECT_EQ(any.nodes_visited, 2u);
    EXPECT_EQ(any.prim_tests, 1u);
    EXPECT_EQ(any.leaves_skipped, 1u);
    EXPECT_EQ(f2b.leaves_skipped, 0u);
  }
}

TEST(InsightTraversal, ModeTotalsOverRays) {
  const Bvh bvh(stacked(), one_per_leaf());
  const std::vector<Ray> rays{down(0.25f, 0.25f), down(0.2f, 0.3f), down(4.0f, 4.0f)};
  const ModeTotals f2b = measure_mode(bvh, rays, QueryOptions{}, TraversalMode::front_to_back, 1);
  EXPECT_EQ(f2b.rays, 3u);
  EXPECT_EQ(f2b.hits, 2u);
  EXPECT_EQ(f2b.nodes_visited, 4u);
  EXPECT_EQ(f2b.nodes_culled, 2u);
  EXPECT_EQ(f2b.prim_tests, 2u);
  EXPECT_NEAR(f2b.per_ray(f2b.nodes_visited), 4.0 / 3.0, 1e-12);
  const ModeTotals xr = measure_mode(bvh, rays, QueryOptions{}, TraversalMode::xray, 1);
  EXPECT_EQ(xr.nodes_visited, 6u);
  EXPECT_EQ(xr.prim_tests, 4u);
  const ModeTotals any = measure_mode(bvh, rays, QueryOptions{}, TraversalMode::any_hit, 1);
  EXPECT_EQ(any.hits, 2u);
  EXPECT_EQ(any.leaves_skipped, 2u);
  EXPECT_EQ(mode_name(TraversalMode::back_to_front), "back-to-front");
}
}  // namespace unity_test_insight_predicted
