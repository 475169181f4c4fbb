// SAH and EPO of BVHs: hand-computed cases, and the reported figures against
// simple independent recomputations written here (recursive walks, their own
// polygon clipping), never the library's own helpers.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <random>
#include <vector>

#include "core/accel/bvh/bvh.h"
#include "core/analysis/epo.h"
#include "core/analysis/sah.h"
#include "tests/core/mt_random.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_sah_epo {

using namespace accelviz;

namespace {

using test_random::uniform;

std::vector<Triangle> soup(std::size_t n, std::uint32_t seed, float size) {
  std::mt19937 rng(seed);
  std::vector<Triangle> tris(n);
  for (Triangle& t : tris) {
    const glm::vec3 c{uniform(rng), uniform(rng), uniform(rng)};
    const auto j = [&] { return (glm::vec3{uniform(rng), uniform(rng), uniform(rng)} - 0.5f) * size; };
    t = {c + j(), c + j(), c + j()};
  }
  return tris;
}

double box_area(const Aabb& b) {
  const double x = static_cast<double>(b.hi.x) - b.lo.x, y = static_cast<double>(b.hi.y) - b.lo.y,
               z = static_cast<double>(b.hi.z) - b.lo.z;
  return 2.0 * (x * y + y * z + z * x);
}

/// SAH by recursion from the root: C_trav·A(n) for inner nodes, C_isect·N·A(n) for leaves, over A(root).
double reference_sah_sum(std::span<const BvhNode> nodes, std::uint32_t i, double ct, double ci) {
  const BvhNode& n = nodes[i];
  if (n.count > 0) return ci * n.count * box_area(n.bounds);
  return ct * box_area(n.bounds) + reference_sah_sum(nodes, n.index, ct, ci) +
         reference_sah_sum(nodes, n.index + 1, ct, ci);
}
double reference_sah(std::span<const BvhNode> nodes, double ct, double ci) {
  return reference_sah_sum(nodes, 0, ct, ci) / box_area(nodes[0].bounds);
}

/// Area of a triangle inside a box: clip the polygon by each of the six
/// half-spaces in turn (kept as a std::vector, one plane per pass), then fan.
double reference_clipped_area(const Triangle& t, const Aabb& b) {
  std::vector<glm::dvec3> poly = {glm::dvec3(t.v0), glm::dvec3(t.v1), glm::dvec3(t.v2)};
  for (int axis = 0; axis < 3; ++axis) {
    for (int side = 0; side < 2; ++side) {
      const double limit = side == 0 ? b.lo[axis] : b.hi[axis];
      const double sign = side == 0 ? 1.0 : -1.0;  // inside: sign·(p - limit) >= 0
      std::vector<glm::dvec3> out;
      for (std::size_t i = 0; i < poly.size(); ++i) {
        const glm::dvec3 p = poly[i], q = poly[(i + 1) % poly.size()];
        const double dp = sign * (p[axis] - limit), dq = sign * (q[axis] - limit);
        if (dp >= 0) out.push_back(p);
        if ((dp >= 0) != (dq >= 0)) out.push_back(p + (q - p) * (dp / (dp - dq)));
      }
      poly = out;
      if (poly.empty()) return 0.0;
    }
  }
  glm::dvec3 n(0.0);
  for (std::size_t i = 1; i + 1 < poly.size(); ++i) n += glm::cross(poly[i] - poly[0], poly[i + 1] - poly[0]);
  return 0.5 * glm::length(n);
}

void collect(std::span<const BvhNode> nodes, std::span<const std::uint32_t> ids, std::uint32_t i,
             std::vector<char>& in_subtree) {
  const BvhNode& n = nodes[i];
  if (n.count > 0) {
    for (std::uint32_t k = n.index; k < n.index + n.count; ++k) in_subtree[ids[k]] = 1;
    return;
  }
  collect(nodes, ids, n.index, in_subtree);
  collect(nodes, ids, n.index + 1, in_subtree);
}

/// EPO by definition: for every node, every triangle outside its subtree,
/// the area of that triangle inside the node's box, weighted by the node's cost.
double reference_epo(std::span<const BvhNode> nodes, std::span<const std::uint32_t> ids, std::span<const Triangle> tris,
                     double ct, double ci) {
  double total_area = 0.0;
  for (const Triangle& t : tris)
    total_area +=
        0.5 * glm::length(glm::cross(glm::dvec3(t.v1) - glm::dvec3(t.v0), glm::dvec3(t.v2) - glm::dvec3(t.v0)));
  double sum = 0.0;
  for (std::uint32_t i = 0; i < nodes.size(); ++i) {
    std::vector<char> mine(tris.size(), 0);
    collect(nodes, ids, i, mine);
    const double cost = nodes[i].count > 0 ? ci * nodes[i].count : ct;
    for (std::size_t p = 0; p < tris.size(); ++p)
      if (!mine[p]) sum += cost * reference_clipped_area(tris[p], nodes[i].bounds);
  }
  return sum / total_area;
}

}  // namespace

// ---- SAH ----

TEST(Sah, HandComputedForTwoLeaves) {
  // Two unit right triangles in the plane z = 0, 2 apart along x:
  // leaf boxes 1×1×0 (area 2 each), root box 4×1×0 (area 8).
  const std::vector<Triangle> tris = {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{3, 0, 0}, {4, 0, 0}, {3, 1, 0}}};
  BvhOptions o;
  o.max_leaf_size = 1;
  o.leaf_size_cap = 1;
  const Bvh bvh(tris, o);
  ASSERT_EQ(bvh.nodes().size(), 3u);
  // 1·C_trav + 2 leaves · (1 prim · C_isect · 2/8)
  EXPECT_DOUBLE_EQ(bvh.build_stats().sah_cost, 1.0 + 0.25 + 0.25);
  EXPECT_DOUBLE_EQ(bvh_sah_cost(bvh.nodes(), 2.0, 3.0), 2.0 + 3.0 * 0.25 * 2);
  o.cost_traversal = 2.0f;
  o.cost_intersect = 3.0f;
  EXPECT_DOUBLE_EQ(Bvh(tris, o).build_stats().sah_cost, 3.5);
}

TEST(Sah, SingleLeafCostsItsPrimitiveCount) {
  const std::vector<Triangle> tris(3, Triangle{{0, 0, 0}, {1, 0, 0}, {0, 1, 1}});
  const Bvh bvh(tris);
  ASSERT_EQ(bvh.nodes().size(), 1u);
  EXPECT_DOUBLE_EQ(bvh.build_stats().sah_cost, 3.0);
}

TEST(Sah, ZeroAreaRootCountsEveryNodeFully) {
  // All triangles on one point: every ratio is 1 (documented convention).
  const std::vector<Triangle> tris(10, Triangle{{1, 1, 1}, {1, 1, 1}, {1, 1, 1}});
  BvhOptions o;
  o.max_leaf_size = 4;
  const Bvh bvh(tris, o);
  double expect = 0;
  for (const BvhNode& n : bvh.nodes()) expect += n.count > 0 ? n.count : 1.0;
  EXPECT_DOUBLE_EQ(bvh.build_stats().sah_cost, expect);
  EXPECT_EQ(bvh_sah_cost({}, 1, 1), 0.0);
}

TEST(Sah, ReportedCostMatchesAnIndependentRecomputation) {
  const auto tris = soup(3000, 1, 0.05f);
  for (BvhSplitter s : {BvhSplitter::binned_sah, BvhSplitter::exact_sah, BvhSplitter::median}) {
    for (float ct : {0.5f, 1.0f, 3.0f}) {
      BvhOptions o;
      o.splitter = s;
      o.cost_traversal = ct;
      o.cost_intersect = 1.5f;
      o.compute_epo = false;
      const Bvh bvh(tris, o);
      EXPECT_NEAR(bvh.build_stats().sah_cost, reference_sah(bvh.nodes(), ct, 1.5), 1e-9 * bvh.build_stats().sah_cost)
          << to_string(s) << " C_trav " << ct;
    }
  }
}

TEST(Sah, TreeShapeMatchesTheStats) {
  const auto tris = soup(1000, 2, 0.05f);
  BvhOptions o;
  o.compute_epo = false;
  const Bvh bvh(tris, o);
  const TreeShape shape = bvh_tree_shape(bvh.nodes());
  EXPECT_EQ(shape.leaf_count, bvh.build_stats().leaf_count);
  EXPECT_EQ(shape.max_depth, bvh.build_stats().max_depth);
  EXPECT_EQ(shape.avg_leaf_depth, bvh.build_stats().avg_leaf_depth);
}

// ---- EPO ----

TEST(Epo, ClippedAreaOfKnownCases) {
  const Triangle t{{0, 0, 0}, {2, 0, 0}, {0, 2, 0}};                               // area 2
  EXPECT_DOUBLE_EQ(clipped_triangle_area(t, {glm::vec3(-1), glm::vec3(3)}), 2.0);  // fully inside
  // x <= 1 cuts off the corner triangle (1,0),(2,0),(1,1) of area 0.5.
  EXPECT_NEAR(clipped_triangle_area(t, {glm::vec3(-1), glm::vec3(1, 3, 3)}), 1.5, 1e-12);
  // The unit square [0,1]² lies wholly inside the triangle.
  EXPECT_NEAR(clipped_triangle_area(t, {glm::vec3(0, 0, -1), glm::vec3(1, 1, 1)}), 1.0, 1e-12);
  EXPECT_EQ(clipped_triangle_area(t, {glm::vec3(5), glm::vec3(6)}), 0.0);              // disjoint
  EXPECT_EQ(clipped_triangle_area(t, {glm::vec3(0, 0, 1), glm::vec3(2, 2, 2)}), 0.0);  // above its plane
  EXPECT_EQ(clipped_triangle_area(t, Aabb::empty()), 0.0);
  // Against the independent clipper on random pairs.
  std::mt19937 rng(3);
  for (int i = 0; i < 2000; ++i) {
    const auto tri = soup(1, rng(), 1.0f)[0];
    glm::vec3 a{uniform(rng), uniform(rng), uniform(rng)}, b{uniform(rng), uniform(rng), uniform(rng)};
    const Aabb box{glm::min(a, b), glm::max(a, b)};
    EXPECT_NEAR(clipped_triangle_area(tri, box), reference_clipped_area(tri, box), 1e-9);
  }
}

TEST(Epo, HandComputedForTwoHalvesOfASquare) {
  // Two triangles splitting the square [0,2]² share one box: each leaf's box
  // holds all of the other triangle. EPO = C_isect·(2 + 2)/(2 + 2) = C_isect.
  const std::vector<Triangle> tris = {{{0, 0, 0}, {2, 0, 0}, {0, 2, 0}}, {{2, 0, 0}, {2, 2, 0}, {0, 2, 0}}};
  BvhOptions o;
  o.max_leaf_size = 1;
  o.leaf_size_cap = 1;
  o.cost_intersect = 3.0f;
  const Bvh bvh(tris, o);
  ASSERT_EQ(bvh.nodes().size(), 3u);
  EXPECT_NEAR(bvh.build_stats().extra.at("epo"), 3.0, 1e-12);
  // Far apart: no overlap, EPO 0.
  const std::vector<Triangle> apart = {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{5, 0, 0}, {6, 0, 0}, {5, 1, 0}}};
  EXPECT_EQ(Bvh(apart, o).build_stats().extra.at("epo"), 0.0);
}

TEST(Epo, ReportedValueMatchesTheDefinition) {
  for (std::uint32_t seed : {4u, 5u}) {
    const auto tris = soup(300, seed, 0.2f);  // large triangles: plenty of overlap
    for (BvhSplitter s : {BvhSplitter::binned_sah, BvhSplitter::median}) {
      BvhOptions o;
      o.splitter = s;
      o.cost_traversal = 1.2f;
      o.cost_intersect = 0.7f;
      const Bvh bvh(tris, o);
      const double ct = o.cost_traversal, ci = o.cost_intersect;  // the float values, widened
      const double ref = reference_epo(bvh.nodes(), bvh.prim_indices(), tris, ct, ci);
      EXPECT_GT(ref, 0.0);
      EXPECT_NEAR(bvh.build_stats().extra.at("epo"), ref, 1e-9 * ref) << to_string(s) << " seed " << seed;
      EXPECT_NEAR(bvh_epo(bvh.nodes(), bvh.prim_indices(), tris, ct, ci, 1), ref, 1e-9 * ref);
    }
  }
}

TEST(Epo, IndependentOfThreadCount) {
  const auto tris = soup(5000, 6, 0.05f);
  BvhOptions o;
  o.compute_epo = false;
  const Bvh bvh(tris, o);
  const double one = bvh_epo(bvh.nodes(), bvh.prim_indices(), tris, 1, 1, 1);
  EXPECT_EQ(bvh_epo(bvh.nodes(), bvh.prim_indices(), tris, 1, 1, 2), one);
  EXPECT_EQ(bvh_epo(bvh.nodes(), bvh.prim_indices(), tris, 1, 1, 4), one);
}

// EPO can take seconds where the build took milliseconds (quadratic when
// every centroid is equal): the app's quit and a newer request waited for it.
// It now asks the build's progress callback whether to go on.
TEST(Epo, ProgressReportsAndCancels) {
  const auto tris = soup(5000, 6, 0.05f);
  BvhOptions o;
  o.compute_epo = false;
  const Bvh bvh(tris, o);
  for (const unsigned threads : {1u, 2u}) {
    SCOPED_TRACE(threads);
    std::atomic<int> calls{0};
    std::atomic<bool> ordered{true};
    std::atomic<double> last{-1.0};
    const double value = bvh_epo(bvh.nodes(), bvh.prim_indices(), tris, 1, 1, threads, [&](double f) {
      ++calls;
      if (!(f >= 0.0 && f < 1.0)) ordered = false;
      last = f;
      return true;
    });
    EXPECT_EQ(value, bvh_epo(bvh.nodes(), bvh.prim_indices(), tris, 1, 1, threads));
    EXPECT_GE(calls.load(), 2) << "5000 triangles in chunks of 256";
    EXPECT_TRUE(ordered.load());
    std::atomic<int> asked{0};
    EXPECT_THROW(bvh_epo(bvh.nodes(), bvh.prim_indices(), tris, 1, 1, threads, [&](double) { return ++asked < 3; }),
                 BuildCancelled);
  }
  // Through the Bvh: a callback that stops once the build has reported 1.0
  // cancels the measurement that follows.
  BvhOptions with = o;
  with.compute_epo = true;
  int after_build = 0;
  EXPECT_THROW(Bvh(tris, with, [&](double f) { return f < 1.0 || ++after_build < 2; }), BuildCancelled);
  EXPECT_EQ(after_build, 2);
}

TEST(Epo, MedianSplitsOverlapMoreThanSah) {
  // The point of the metric: the median tree's boxes cut through more foreign geometry.
  const auto tris = soup(4000, 7, 0.08f);
  BvhOptions o;
  const double sah_tree = Bvh(tris, o).build_stats().extra.at("epo");
  o.splitter = BvhSplitter::median;
  const double median_tree = Bvh(tris, o).build_stats().extra.at("epo");
  EXPECT_LT(sah_tree, median_tree);
}

TEST(Epo, RejectsMismatchedInput) {
  const auto tris = soup(10, 8, 0.1f);
  const Bvh bvh(tris);
  const std::vector<Triangle> fewer(tris.begin(), tris.begin() + 5);
  EXPECT_THROW(bvh_epo(bvh.nodes(), bvh.prim_indices(), fewer, 1, 1), std::invalid_argument);
  EXPECT_EQ(bvh_epo({}, {}, {}, 1, 1), 0.0);
}
}  // namespace unity_test_sah_epo
