// Octree (core/accel/octree): subdivision rules and invariants (leaves hold
// exactly the triangles overlapping their padded cell, SAH recomputed), the
// ordered traversal's named cases (a hit beyond the current leaf, rays in
// mid-planes, front-to-back order), options and degenerate inputs.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

#include "core/accel/brute_force.h"
#include "core/accel/kdtree/spatial_traversal.h"
#include "core/accel/octree/octree.h"
#include "core/geometry/tri_box_overlap.h"
#include "tests/core/spatial_build_checks.h"
#include "tests/core/spatial_test_scenes.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_octree {

using namespace accelviz;
using namespace accelviz::test_scenes;

namespace {

using Scene = std::vector<Triangle>;

struct Cell {
  std::uint32_t index;
  Aabb box;
  int depth;
};

std::vector<Cell> walk(const Octree& o) {
  std::vector<Cell> out;
  if (o.nodes().empty()) return out;
  std::vector<Cell> stack{{0, o.root_box(), 0}};
  while (!stack.empty()) {
    const Cell c = stack.back();
    stack.pop_back();
    out.push_back(c);
    const OctreeNode& n = o.nodes()[c.index];
    if (n.is_leaf()) continue;
    for (int k = 0; k < 8; ++k) stack.push_back({n.index + k, Octree::child_box(c.box, k), c.depth + 1});
  }
  return out;
}

::testing::AssertionResult agrees(const Octree& o, const BruteForce& bf, const Ray& r, const QueryOptions& qo = {}) {
  const Hit a = o.closest_hit(r, qo), b = bf.closest_hit(r, qo);
  RayStats st;
  const Hit c = o.closest_hit(r, qo, &st);
  if (a.valid() != b.valid() || c.prim != a.prim || o.any_hit(r, qo) != b.valid())
    return ::testing::AssertionFailure() << "validity: octree " << a.valid() << " brute " << b.valid();
  if (a.valid() && a.prim != b.prim && std::fabs(a.t - b.t) > 1e-6f * std::max(1.0f, std::fabs(b.t)))
    return ::testing::AssertionFailure() << "octree prim " << a.prim << " t " << a.t << ", brute prim " << b.prim
                                         << " t " << b.t;
  return ::testing::AssertionSuccess();
}

}  // namespace

TEST(Octree, OptionsAreValidated) {
  const Scene s = soup(1, 10, 0.1f);
  OctreeOptions o;
  o.max_depth = -1;
  EXPECT_THROW(Octree(s, o), std::invalid_argument);
  o.max_depth = 17;
  try {
    Octree t(s, o);
    ADD_FAILURE() << "max_depth 17 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("max_depth"), std::string::npos) << e.what();
  }
  o = {};
  o.max_leaf_size = 0;
  EXPECT_THROW(Octree(s, o), std::invalid_argument);
  EXPECT_NO_THROW(validate(OctreeOptions{}));
}

TEST(Octree, EmptyAndOnePrimitive) {
  const Octree none(Scene{});
  EXPECT_EQ(none.name(), "octree");
  EXPECT_EQ(none.build_stats().node_count, 0u);
  EXPECT_FALSE(none.closest_hit(Ray({0, 0, -1}, {0, 0, 1}), {}).valid());
  EXPECT_FALSE(none.any_hit(Ray({0, 0, -1}, {0, 0, 1}), {}));
  const Scene one{{{-1, -1, 2}, {1, -1, 2}, {0, 1, 2}}};
  const Octree o(one);
  EXPECT_EQ(o.build_stats().node_count, 1u);
  const Hit h = o.closest_hit(Ray({0, 0, 0}, {0, 0, 1}), {});
  ASSERT_TRUE(h.valid());
  EXPECT_FLOAT_EQ(h.t, 2.0f);
}

TEST(Octree, RootIsACubeAroundTheScene) {
  const Scene s = soup(2, 100, 0.1f, {0, 0, 0}, {4, 1, 2});
  const Octree o(s);
  const Aabb r = o.root_box();
  Aabb b;
  for (const Triangle& t : s) b.extend(t.bounds());
  EXPECT_TRUE(r.contains(b));
  EXPECT_EQ(r.lo, b.lo);
  const glm::vec3 e = r.extent();
  EXPECT_NEAR(e.x, e.y, 1e-5f * e.x);
  EXPECT_NEAR(e.x, e.z, 1e-5f * e.x);
}

TEST(Octree, LeavesHoldExactlyTheOverlappingTriangles) {
  const Scene s = soup(3, 800, 0.1f);
  OctreeOptions opts;
  opts.max_leaf_size = 4;
  const Octree o(s, opts);
  const float pad = spatial::cell_padding(o.root_box().lo, o.root_box().hi);
  std::vector<int> refs(s.size(), 0);
  std::uint64_t leaves = 0, empty = 0;
  double sah = 0.0;
  std::uint32_t deepest = 0;
  const std::vector<Cell> cells = walk(o);
  for (const Cell& c : cells) {
    const OctreeNode& n = o.nodes()[c.index];
    if (!n.is_leaf()) {
      sah += c.box.half_area();
      continue;
    }
    ++leaves;
    empty += n.count == 0;
    sah += n.count * c.box.half_area();
    deepest = std::max<std::uint32_t>(deepest, c.depth);
    std::vector<bool> in_leaf(s.size(), false);
    for (std::uint32_t k = 0; k < n.count; ++k) {
      in_leaf[o.prim_refs()[n.index + k]] = true;
      ++refs[o.prim_refs()[n.index + k]];
    }
    const Aabb cell = padded_box(c.box, pad);
    for (std::size_t i = 0; i < s.size(); ++i) {
      if (in_leaf[i] != triangle_box_overlap(s[i], cell))
        ADD_FAILURE() << "leaf " << c.index << " triangle " << i << " listed " << in_leaf[i];
    }
  }
  for (std::size_t i = 0; i < s.size(); ++i) EXPECT_GT(refs[i], 0);
  const BuildStats& st = o.build_stats();
  EXPECT_EQ(cells.size(), st.node_count);
  EXPECT_EQ(leaves, st.leaf_count);
  EXPECT_EQ(deepest, st.max_depth);
  EXPECT_EQ(st.extra.at("empty_leaves"), static_cast<double>(empty));
  EXPECT_NEAR(st.sah_cost, sah / o.root_box().half_area(), 1e-6 * st.sah_cost);
  // Nodes, references and the triangles it copies (36 bytes each).
  EXPECT_EQ(st.memory_bytes, st.node_count * 8 + o.prim_refs().size() * 4 + s.size() * 36);
  EXPECT_GT(st.max_depth, 2u);
}

TEST(Octree, SubdivisionFollowsMaxLeafSizeAndDepth) {
  // Well-separated small triangles: without the cost rule, every leaf with
  // more than max_leaf_size triangles sits at max_depth.
  const Scene s = soup(4, 2000, 0.004f);
  for (int depth : {3, 6}) {
    OctreeOptions o;
    o.max_depth = depth;
    o.max_leaf_size = 2;
    o.cost_termination = false;
    const Octree t(s, o);
    EXPECT_EQ(t.build_stats().max_depth, static_cast<std::uint32_t>(depth));
    for (const Cell& c : walk(t)) {
      const OctreeNode& n = t.nodes()[c.index];
      if (n.is_leaf() && n.count > 2u) {
        EXPECT_EQ(c.depth, depth) << "leaf with " << n.count << " triangles";
      }
      if (!n.is_leaf()) {
        EXPECT_LT(c.depth, depth);
      }
    }
  }
  OctreeOptions flat;
  flat.max_depth = 0;
  EXPECT_EQ(Octree(s, flat).build_stats().node_count, 1u);
}

// Named case: as in the K-D tree, a large triangle met first in a cell that
// the ray leaves before the hit, with a nearer triangle in a later cell.
TEST(Octree, HitBeyondTheCurrentLeafDoesNotEndTheSearch) {
  // A lies in the plane x = 2 + 2y and meets the ray (y = z = 0, along +x)
  // at x = 2, but reaches back to x = -2 below the ray; B is small, at
  // x = 1.5. The root cube [-2, 4] x [-2, 4] x [-1, 5] splits at x = 1: the
  // ray's first octant holds A's lower part only, so A is hit there beyond
  // the octant's exit (x = 1) while B waits in the next octant.
  Scene s;
  s.push_back({{-2, -2, -1}, {4, 1, -1}, {2, 0, 3}});
  s.push_back({{1.5f, -0.2f, -0.2f}, {1.5f, 0.2f, -0.2f}, {1.5f, 0, 0.2f}});
  OctreeOptions o;
  o.max_leaf_size = 1;
  o.cost_termination = false;
  const Octree t(s, o);
  const Ray ray({-5, 0, 0}, {1, 0, 0});
  VisitTrace tr;
  const Hit h = t.closest_hit(ray, {}, nullptr, &tr);
  ASSERT_TRUE(h.valid());
  EXPECT_EQ(h.prim, 1u);
  EXPECT_FLOAT_EQ(h.t, 6.5f);
  bool a_beyond = false;
  float exit = kInfinity;
  for (const VisitStep& st : tr.steps) {
    if (st.kind == VisitStep::Kind::node_entered && t.nodes()[st.id].is_leaf()) exit = st.t_exit;
    if (st.kind == VisitStep::Kind::prim_hit && st.id == 0u && st.t_entry > exit) a_beyond = true;
  }
  EXPECT_TRUE(a_beyond) << "A was not met beyond its leaf first";
  EXPECT_EQ(Octree(s).closest_hit(ray, {}).prim, 1u);
}

// Named case: rays lying in mid-planes of cells (origin on the plane, ±0
// direction component on that axis) must search both sides.
TEST(Octree, RaysLyingInMidPlanes) {
  Scene s = soup(6, 400, 0.15f);
  const Octree o(s);
  const BruteForce bf(s);
  Rng rng{7};
  int n = 0, hits = 0;
  for (const Cell& c : walk(o)) {
    if (o.nodes()[c.index].is_leaf() || c.depth > 3) continue;
    const glm::vec3 mid = 0.5f * (c.box.lo + c.box.hi);
    for (int k = 0; k < 30; ++k) {
      const int a = k % 3;
      glm::vec3 p = rng.in_box(c.box.lo, c.box.hi), d = rng.unit();
      p[a] = mid[a];
      d[a] = (k & 4) ? 0.0f : -0.0f;
      if (k & 8) p[(a + 1) % 3] = mid[(a + 1) % 3];  // on two mid-planes: the line where four octants meet
      if (k & 8) d[(a + 1) % 3] = (k & 16) ? 0.0f : -0.0f;
      EXPECT_TRUE(agrees(o, bf, Ray(p - 3.0f * d, d))) << "cell " << c.index << " k " << k;
      ++n;
      hits += bf.closest_hit(Ray(p - 3.0f * d, d), {}).valid();
    }
  }
  EXPECT_GT(n, 100);
  EXPECT_GT(hits, n / 5);
}

TEST(Octree, OrderedTraversalVisitsLessThanFixedOrder) {
  const Scene s = soup(8, 3000, 0.03f);
  const Octree o(s);
  QueryOptions unordered;
  unordered.ordered = false;
  RayStats so, su;
  Rng rng{9};
  for (int i = 0; i < 2000; ++i) {
    const Ray r{3.0f * rng.unit(), rng.unit()};
    const Hit a = o.closest_hit(r, {}, &so), b = o.closest_hit(r, unordered, &su);
    ASSERT_EQ(a.prim, b.prim);
  }
  EXPECT_LT(so.prim_tests, su.prim_tests);
  EXPECT_LT(so.nodes_visited, su.nodes_visited);
  EXPECT_GT(so.empty_cells, 0u);
  EXPECT_GT(so.nodes_culled, 0u);
}

TEST(Octree, DegenerateInputsTerminate) {
  Rng rng{10};
  Scene same;  // all centroids equal: triangles crossing at one point
  for (int i = 0; i < 300; ++i) {
    const glm::vec3 da = rng.unit();
    const glm::vec3 a = da * rng.range(0.05f, 1.0f);
    const glm::vec3 db = rng.unit();
    const glm::vec3 b = db * rng.range(0.05f, 1.0f);
    same.push_back({a, b, -a - b});
  }
  const Scene dup(200, Triangle{{0, 0, 0}, {1, 0, 0}, {0, 1, 0.5f}});
  const Scene points(100, Triangle{{1, 2, 3}, {1, 2, 3}, {1, 2, 3}});
  Scene wall;
  for (int i = 0; i < 40; ++i)
    for (int j = 0; j < 40; ++j)
      wall.push_back({{0.05f * i, 0.05f * j, 1}, {0.05f * i + 0.05f, 0.05f * j, 1}, {0.05f * i, 0.05f * j + 0.05f, 1}});
  for (const Scene* s : std::vector<const Scene*>{&same, &dup, &points, &wall}) {
    OctreeOptions fine;
    fine.max_leaf_size = 1;
    fine.max_depth = 12;
    const Octree o(*s, fine);
    // The depth cap is what ends the subdivision of inseparable triangles; the node count then
    // depends on how the triangles cross (all centroids equal: 77,705 nodes for one draw of 300),
    // and the bound only catches a subdivision gone far beyond that.
    EXPECT_LE(o.build_stats().max_depth, 12u) << "the depth cap was passed";
    EXPECT_LT(o.build_stats().node_count, 500 * s->size() + 100) << "runaway subdivision";
    const BruteForce bf(*s);
    for (int i = 0; i < 300; ++i) {
      const glm::vec3 c(0.5f, 0.5f, 0.5f);
      const glm::vec3 org = c + 3.0f * rng.unit();
      ASSERT_TRUE(agrees(o, bf, Ray(org, c + rng.unit() - org)));
    }
  }
  // Coincident triangles cannot be separated: the root stays a leaf.
  EXPECT_EQ(Octree(dup).build_stats().node_count, 1u);
  // A small cluster in a corner of a big scene is still subdivided (the cell
  // shrinks around it).
  Scene cluster = soup(11, 200, 0.001f, glm::vec3(0.9f), glm::vec3(0.91f));
  cluster.push_back({{-1, -1, -1}, {-0.99f, -1, -1}, {-1, -0.99f, -1}});
  EXPECT_GT(Octree(cluster).build_stats().max_depth, 5u);
}

TEST(Octree, ProgressAndCancellation) {
  const Scene s = soup(12, 5000, 0.02f);
  double last = 0.0;
  int calls = 0;
  const Octree o(s, {}, [&](double f) {
    EXPECT_GE(f, last);
    last = f;
    ++calls;
    return true;
  });
  EXPECT_GT(calls, 5);
  EXPECT_DOUBLE_EQ(last, 1.0);
  EXPECT_THROW(Octree(s, {}, [](double f) { return f < 0.5; }), BuildCancelled);
}

// A scene large enough for the parallel build (16,384 triangles or more):
// random triangles, an axis-aligned subdivided cube (triangles in the cells'
// mid-planes) and a clump of 3,000 coincident triangles across the root's
// mid-planes (cells that stop splitting with more triangles than a job may
// have: leaves of the tree's top, between the jobs) give the same node
// array, references and figures on any thread count as on one.
TEST(Octree, SameTreeOnAnyThreadCount) {
  Scene s = soup(9, 30000, 0.03f);
  const Scene cube = subdivided_cube(glm::vec3(-0.5f), 1.0f, 16);
  s.insert(s.end(), cube.begin(), cube.end());
  const Triangle across{{-0.3f, -0.3f, -0.3f}, {0.3f, -0.2f, 0.1f}, {0.1f, 0.3f, 0.2f}};
  for (int i = 0; i < 3000; ++i) s.push_back(across);
  ASSERT_GE(s.size(), 16384u);
  OctreeOptions o;
  o.threads = 1;
  const Octree one(s, o);
  for (unsigned t : {2u, 3u, 5u}) {
    o.threads = t;
    EXPECT_TRUE(same_tree(Octree(s, o), one)) << t << " threads";
  }
  EXPECT_GT(one.nodes().size(), 1000u);
  EXPECT_GT(one.build_stats().extra.at("empty_leaves"), 0.0);  // empty leaves, whose offsets must match too
}

// The parallel build reports progress in order, from whichever thread, and
// stops on all threads at the first refusal.
TEST(Octree, ParallelBuildProgressAndCancellation) {
  OctreeOptions o;
  o.threads = 2;
  check_parallel_progress_and_cancellation<Octree>(soup(17, 40000, 0.02f), o);
}
}  // namespace unity_test_octree
