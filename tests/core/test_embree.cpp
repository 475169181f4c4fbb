#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/accel/brute_force.h"
#include "core/accel/embree_backend.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_embree {

using namespace accelviz;

#ifdef ACCELVIZ_HAVE_EMBREE

namespace {

/// Seeded soup of small random triangles in [-1, 1]^3.
std::vector<Triangle> random_soup(std::size_t n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(-1.0f, 1.0f), off(-0.15f, 0.15f);
  std::vector<Triangle> tris;
  for (std::size_t i = 0; i < n; ++i) {
    const glm::vec3 c(pos(rng), pos(rng), pos(rng));
    tris.push_back({c + glm::vec3(off(rng), off(rng), off(rng)), c + glm::vec3(off(rng), off(rng), off(rng)),
                    c + glm::vec3(off(rng), off(rng), off(rng))});
  }
  return tris;
}

/// Rays from outside and inside the soup, random directions; a third are
/// segments with finite tmax, some start at tmin > 0.
std::vector<Ray> random_rays(std::size_t n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), len(0.1f, 3.0f);
  std::vector<Ray> rays;
  while (rays.size() < n) {
    const glm::vec3 d(u(rng), u(rng), u(rng));
    if (glm::dot(d, d) < 1e-4f) continue;
    const bool outside = rays.size() % 2 == 0;
    const glm::vec3 o = outside ? glm::vec3(u(rng), u(rng), u(rng)) * 3.0f : glm::vec3(u(rng), u(rng), u(rng));
    const float tmin = rays.size() % 5 == 0 ? 0.2f : 0.0f;
    const float tmax = rays.size() % 3 == 0 ? tmin + len(rng) : kInfinity;
    rays.emplace_back(o, outside ? glm::normalize(-o + 0.5f * d) : d, tmin, tmax);
  }
  return rays;
}

bool same_t(float a, float b) {
  return std::abs(a - b) <= 1e-4f * std::max(1.0f, std::abs(b));
}

}  // namespace

TEST(Embree, ClosestAndAnyHitAgreeWithBruteForce) {
  const std::vector<Triangle> tris = random_soup(3000, 11);
  const std::vector<Ray> rays = random_rays(4000, 12);
  const BruteForce reference(tris);
  const EmbreeAccelerator embree(tris);
  EXPECT_EQ(embree.name(), "embree");
  const QueryOptions q;
  int hits = 0, misses = 0, ties = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const Hit expected = reference.closest_hit(rays[i], q);
    const Hit got = embree.closest_hit(rays[i], q);
    ASSERT_EQ(got.valid(), expected.valid()) << "ray " << i;
    if (expected.valid()) {
      ++hits;
      EXPECT_TRUE(same_t(got.t, expected.t)) << "ray " << i << ": " << got.t << " vs " << expected.t;
      if (got.prim != expected.prim) {
        ++ties;  // allowed only as a tie in t (checked above)
      } else {
        EXPECT_NEAR(got.u, expected.u, 1e-3f);
        EXPECT_NEAR(got.v, expected.v, 1e-3f);
        EXPECT_EQ(got.ng, expected.ng);
      }
    } else {
      ++misses;
    }
    EXPECT_EQ(embree.any_hit(rays[i], q), reference.any_hit(rays[i], q)) << "ray " << i;
  }
  // The data exercises both outcomes.
  EXPECT_GT(hits, 500);
  EXPECT_GT(misses, 500);
  EXPECT_LT(ties, 5);
}

TEST(Embree, LeavesRayStatsAtZero) {
  const std::vector<Triangle> tris = random_soup(100, 3);
  const EmbreeAccelerator embree(tris);
  RayStats st;
  embree.closest_hit(Ray({0, 0, -5}, {0, 0, 1}), {}, &st);
  embree.any_hit(Ray({0, 0, -5}, {0, 0, 1}), {}, &st);
  EXPECT_EQ(st.nodes_visited + st.prim_tests + st.box_tests, 0u);
  EXPECT_GT(embree.build_stats().memory_bytes, 100u * sizeof(Triangle));
  EXPECT_GE(embree.build_stats().build_ms, 0.0);
}

TEST(Embree, EmptySceneMissesEverything) {
  const EmbreeAccelerator embree(std::span<const Triangle>{});
  EXPECT_FALSE(embree.closest_hit(Ray({0, 0, 0}, {0, 0, 1}), {}).valid());
  EXPECT_FALSE(embree.any_hit(Ray({0, 0, 0}, {0, 0, 1}), {}));
}

TEST(Embree, QualityAndRobustOptionsGiveTheSameHits) {
  const std::vector<Triangle> tris = random_soup(500, 5);
  const std::vector<Ray> rays = random_rays(500, 6);
  const EmbreeAccelerator medium(tris);
  for (EmbreeQuality quality : {EmbreeQuality::low, EmbreeQuality::high}) {
    const EmbreeAccelerator other(tris, EmbreeOptions{.quality = quality, .robust = true, .threads = 1});
    for (const Ray& r : rays) {
      const Hit a = medium.closest_hit(r, {}), b = other.closest_hit(r, {});
      ASSERT_EQ(a.valid(), b.valid());
      if (a.valid()) {
        EXPECT_TRUE(same_t(a.t, b.t));
      }
    }
  }
}

TEST(Embree, BinaryBvhSahOfOneTriangleIsOneIntersection) {
  const std::vector<Triangle> one = {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}};
  const EmbreeBvhFigures fig = embree_binary_bvh_sah(one, 1.0f, 2.5f, 1);
  EXPECT_DOUBLE_EQ(fig.sah_cost, 2.5);  // a root leaf with one primitive: C_isect · 1 · A/A
  EXPECT_EQ(fig.node_count, 1u);
  EXPECT_EQ(fig.leaf_count, 1u);
}

TEST(Embree, BinaryBvhSahOfTwoFarTrianglesSplits) {
  // Two unit triangles far apart: splitting is far cheaper than one leaf of 2,
  // so with min_leaf 1 the tree is a root and two leaves, and the SAH follows
  // from the boxes: C_trav + C_isect·(A(b0) + A(b1)) / A(root).
  const std::vector<Triangle> two = {{{0, 0, 0}, {1, 0, 0}, {0, 1, 1}}, {{10, 0, 0}, {11, 0, 0}, {10, 1, 1}}};
  const EmbreeBvhFigures fig = embree_binary_bvh_sah(two, 1.0f, 1.0f, 1, /*min_leaf=*/1, /*max_leaf=*/4);
  EXPECT_EQ(fig.node_count, 3u);
  EXPECT_EQ(fig.leaf_count, 2u);
  EXPECT_EQ(fig.max_depth, 1u);
  const double a_leaf = 2.0 * (1 * 1 + 1 * 1 + 1 * 1);
  const double a_root = 2.0 * (11 * 1 + 1 * 1 + 1 * 11);
  EXPECT_NEAR(fig.sah_cost, 1.0 + 2.0 * a_leaf / a_root, 1e-9);
}

TEST(Embree, BinaryBvhOfSoupIsAFullBinaryTree) {
  const std::vector<Triangle> tris = random_soup(5000, 21);
  const EmbreeBvhFigures fig = embree_binary_bvh_sah(tris, 1.0f, 1.0f, 2);
  EXPECT_EQ(fig.node_count, 2 * fig.leaf_count - 1);
  // Leaves hold between 1 and 16 primitives, so there are at least N/16 of them.
  EXPECT_GE(fig.leaf_count, tris.size() / 16);
  // A real hierarchy: far cheaper than testing everything, dearer than one test.
  EXPECT_GT(fig.sah_cost, 1.0);
  EXPECT_LT(fig.sah_cost, 0.05 * static_cast<double>(tris.size()));
  EXPECT_THROW(embree_binary_bvh_sah(tris, 1.0f, 1.0f, 1, 4, 64), std::invalid_argument);
}

#else

TEST(Embree, NotBuilt) {
  GTEST_SKIP() << "built without ACCELVIZ_WITH_EMBREE";
}

#endif
}  // namespace unity_test_embree
