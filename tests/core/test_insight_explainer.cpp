// Insight: the binned-SAH explainer (bucket histogram, bounds, cost curve,
// chosen plane, leaf-vs-split) against hand-computed cases, and against what
// the builder actually did.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "core/accel/bvh/bvh.h"
#include "core/analysis/insight/sah_explainer.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_insight_explainer {

using namespace accelviz;

namespace {

// Unit cubes (half size 0.5) centred at x = 0, 1, 2 and 10 (y = z = 0).
// A box of x-extent e and unit y, z extents has half area e·1 + 1·1 + 1·e = 2e + 1.
struct Cubes {
  std::vector<Aabb> bounds;
  std::vector<glm::vec3> centroids;
};
Cubes cubes(std::initializer_list<float> xs) {
  Cubes c;
  for (const float x : xs) {
    c.centroids.push_back({x, 0.0f, 0.0f});
    c.bounds.push_back(Aabb{{x - 0.5f, -0.5f, -0.5f}, {x + 0.5f, 0.5f, 0.5f}});
  }
  return c;
}

BvhOptions opts(int buckets, int max_leaf = 1, float c_trav = 1.0f) {
  BvhOptions o;
  o.buckets = buckets;
  o.small_node_buckets = false;  // the hand-computed cases bin their few primitives into B buckets
  o.max_leaf_size = max_leaf;
  o.leaf_size_cap = 16;
  o.cost_traversal = c_trav;
  return o;
}

}  // namespace

TEST(InsightExplainer, FourBucketsHandComputed) {
  const Cubes c = cubes({0, 1, 2, 10});
  const SplitExplanation e = explain_binned_split(c.bounds, c.centroids, opts(4));
  EXPECT_EQ(e.prims, 4u);
  EXPECT_EQ(e.buckets, 4);
  EXPECT_FALSE(e.axes[1].usable);  // centroids do not spread in y or z
  EXPECT_FALSE(e.axes[2].usable);
  const AxisExplanation& x = e.axes[0];
  ASSERT_TRUE(x.usable);
  ASSERT_EQ(x.buckets.size(), 4u);
  // k = 4/10: centroids 0, 1, 2 -> bucket 0 (0, 0.4, 0.8); 10 -> bucket 3.
  EXPECT_EQ(x.buckets[0].count, 3u);
  EXPECT_EQ(x.buckets[1].count, 0u);
  EXPECT_EQ(x.buckets[2].count, 0u);
  EXPECT_EQ(x.buckets[3].count, 1u);
  EXPECT_FLOAT_EQ(x.buckets[0].lo, 0.0f);
  EXPECT_FLOAT_EQ(x.buckets[0].hi, 2.5f);
  EXPECT_FLOAT_EQ(x.buckets[3].hi, 10.0f);
  EXPECT_FLOAT_EQ(x.buckets[0].box.lo.x, -0.5f);
  EXPECT_FLOAT_EQ(x.buckets[0].box.hi.x, 2.5f);
  EXPECT_TRUE(x.buckets[1].box.is_empty());
  ASSERT_EQ(x.plane.size(), 3u);
  EXPECT_FLOAT_EQ(x.plane[0], 2.5f);
  EXPECT_FLOAT_EQ(x.plane[2], 7.5f);
  // Every plane leaves {0,1,2} | {10}: (A_L·N_L + A_R·N_R)/A_N = (7·3 + 3·1)/23.
  for (int b = 0; b < 3; ++b) {
    EXPECT_EQ(x.left[b], 3u);
    EXPECT_NEAR(x.cost[b], 1.0 + 24.0 / 23.0, 1e-6) << b;
  }
  EXPECT_EQ(e.chosen_axis, 0);
  EXPECT_EQ(e.chosen_plane, 0);  // equal costs, equal balance: the first
  EXPECT_EQ(e.chosen_left, 3u);
  EXPECT_NEAR(e.split_cost, 1.0 + 24.0 / 23.0, 1e-6);
  EXPECT_DOUBLE_EQ(e.leaf_cost, 4.0);
  EXPECT_TRUE(e.leaf_allowed);
  EXPECT_EQ(e.decision, SplitDecision::split);
}

TEST(InsightExplainer, BucketCountChangesTheCurve) {
  const Cubes c = cubes({0, 1, 2, 10});
  // B = 8: k = 0.8, buckets 0 {0, 1}, 1 {2}, 7 {10}. Plane 0 leaves {0,1} | {2,10}:
  // (5·2 + 19·2)/23 = 48/23; planes 1..6 leave {0,1,2} | {10}: 24/23.
  const SplitExplanation e = explain_binned_split(c.bounds, c.centroids, opts(8));
  const AxisExplanation& x = e.axes[0];
  ASSERT_EQ(x.cost.size(), 7u);
  EXPECT_EQ(x.buckets[0].count, 2u);
  EXPECT_EQ(x.buckets[1].count, 1u);
  EXPECT_EQ(x.buckets[7].count, 1u);
  EXPECT_NEAR(x.cost[0], 1.0 + 48.0 / 23.0, 1e-6);
  for (int b = 1; b < 7; ++b) EXPECT_NEAR(x.cost[b], 1.0 + 24.0 / 23.0, 1e-6) << b;
  EXPECT_EQ(e.chosen_plane, 1);
  // B = 2: one candidate.
  const SplitExplanation two = explain_binned_split(c.bounds, c.centroids, opts(2));
  EXPECT_EQ(two.axes[0].cost.size(), 1u);
  EXPECT_EQ(two.axes[0].buckets[0].count, 3u);
}

TEST(InsightExplainer, LeftCountsGrowAcrossThePlanes) {
  // Centroids 0, 10, 10 with B = 4: bucket 0 {0}, bucket 3 {10, 10}; every plane leaves 1 | 2:
  // (A_L·1 + A_R·2)/A_N with A_L = 3 (x extent 1), A_R = 3, A_N = 2·11 + 1 = 23.
  const Cubes d = cubes({0, 10, 10});
  const SplitExplanation f = explain_binned_split(d.bounds, d.centroids, opts(4));
  EXPECT_EQ(f.axes[0].buckets[0].count, 1u);
  EXPECT_EQ(f.axes[0].buckets[3].count, 2u);
  for (std::size_t b = 0; b < 3; ++b) {
    EXPECT_EQ(f.axes[0].left[b], 1u);
    EXPECT_NEAR(f.axes[0].cost[b], 1.0 + 9.0 / 23.0, 1e-6);
  }
}

TEST(InsightExplainer, LeafAlwaysLeafAndUnsplittable) {
  const Cubes c = cubes({0, 1, 2, 10});
  // Expensive traversal: a leaf (4) beats splitting (10 + 24/23).
  const SplitExplanation leaf = explain_binned_split(c.bounds, c.centroids, opts(4, 1, 10.0f));
  EXPECT_EQ(leaf.decision, SplitDecision::leaf);
  EXPECT_NEAR(leaf.split_cost, 10.0 + 24.0 / 23.0, 1e-5);
  // At most max_leaf_size primitives: a leaf without asking (the curve is still shown).
  const SplitExplanation always = explain_binned_split(c.bounds, c.centroids, opts(4, 4));
  EXPECT_EQ(always.decision, SplitDecision::always_leaf);
  EXPECT_EQ(always.axes[0].cost.size(), 3u);
  // All centroids on one point (boxes of different sizes): nothing to bin.
  std::vector<Aabb> b{Aabb{{-1, -1, -1}, {1, 1, 1}}, Aabb{{-2, -2, -2}, {2, 2, 2}}, Aabb{{-3, -1, -1}, {3, 1, 1}}};
  std::vector<glm::vec3> centres(3, glm::vec3(0.0f));
  const SplitExplanation u = explain_binned_split(b, centres, opts(16));
  EXPECT_EQ(u.decision, SplitDecision::unsplittable);
  EXPECT_EQ(u.chosen_axis, -1);
  for (const auto& ax : u.axes) {
    EXPECT_FALSE(ax.usable);
    EXPECT_TRUE(ax.cost.empty());
  }
  EXPECT_TRUE(std::isnan(u.split_cost));
  EXPECT_STREQ(to_string(u.decision), "unsplittable");
  // Bad input.
  std::vector<glm::vec3> short_centres(2);
  EXPECT_THROW(explain_binned_split(b, short_centres, opts(16)), std::invalid_argument);
  EXPECT_THROW(explain_binned_split(b, centres, opts(1)), std::invalid_argument);
}

TEST(InsightExplainer, MatchesWhatTheBuilderDid) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<Triangle> tris(300);
  for (Triangle& t : tris) {
    const glm::vec3 c{u(rng), u(rng), u(rng)};
    t = {c, c + glm::vec3(0.05f * u(rng), 0.02f, 0.0f), c + glm::vec3(0.0f, 0.03f * u(rng), 0.04f)};
  }
  BvhOptions o;
  o.compute_epo = false;
  // With small_node_buckets the root (300 primitives) bins into min(B, 19)
  // buckets, its children into fewer: the explainer must use the same counts.
  for (const int buckets : {4, 16, 64, -16, -64}) {
    o.buckets = std::abs(buckets);
    o.small_node_buckets = buckets > 0;
    const Bvh bvh(tris, o);
    const auto nodes = bvh.nodes();
    const auto prims_below = [&](std::uint32_t n) {
      std::uint32_t count = 0;
      std::vector<std::uint32_t> st{n};
      while (!st.empty()) {
        const BvhNode& x = nodes[st.back()];
        st.pop_back();
        if (x.is_leaf())
          count += x.count;
        else {
          st.push_back(x.index);
          st.push_back(x.index + 1);
        }
      }
      return count;
    };
    // The root and its children: the explained split leaves exactly as many
    // primitives on the left as the tree's left child holds.
    for (const std::uint32_t node : {0u, nodes[0].index, nodes[0].index + 1}) {
      if (nodes[node].is_leaf()) continue;
      const SplitExplanation e = explain_bvh_node(bvh, node, o);
      EXPECT_EQ(e.prims, prims_below(node));
      ASSERT_EQ(e.decision, SplitDecision::split) << buckets << " " << node;
      EXPECT_EQ(e.chosen_left, prims_below(nodes[node].index)) << buckets << " " << node;
    }
  }
  EXPECT_THROW(explain_bvh_node(Bvh(tris, o), 1u << 30, o), std::out_of_range);
}
}  // namespace unity_test_insight_explainer
