// K-D tree (core/accel/kdtree): named hard cases of the traversal (a
// straddling triangle hit beyond the current leaf, rays lying in split
// planes, split distances equal to tmin/tmax), mailboxing and its
// statistics, the build's invariants (every triangle referenced where it
// overlaps, SAH recomputed independently), options and degenerate inputs.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "core/accel/brute_force.h"
#include "core/accel/kdtree/kdtree.h"
#include "core/geometry/tri_box_overlap.h"
#include "tests/core/spatial_build_checks.h"
#include "tests/core/spatial_test_scenes.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_kdtree {

using namespace accelviz;
using namespace accelviz::test_scenes;

namespace {

using Scene = std::vector<Triangle>;

// Axis-aligned boxes side by side on a lattice: faces in shared planes.
Scene lattice() {
  Scene s;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 2; ++j) box(s, glm::vec3(i, j, 0), glm::vec3(i + 1, j + 1, 1 + 0.5f * i));
  return s;
}

struct NodeInfo {
  std::uint32_t index;
  Aabb box;
  int depth;
};

// Every node with its cell box, by walking the flat array.
std::vector<NodeInfo> walk(const KdTree& kd) {
  std::vector<NodeInfo> out;
  if (kd.nodes().empty()) return out;
  std::vector<NodeInfo> stack{{0, kd.bounds(), 0}};
  while (!stack.empty()) {
    const NodeInfo n = stack.back();
    stack.pop_back();
    out.push_back(n);
    const KdNode& node = kd.nodes()[n.index];
    if (node.is_leaf()) continue;
    Aabb below = n.box, above = n.box;
    below.hi[node.axis()] = node.split();
    above.lo[node.axis()] = node.split();
    stack.push_back({n.index + 1, below, n.depth + 1});
    stack.push_back({node.above_child(), above, n.depth + 1});
  }
  return out;
}

// Brute force and the tree agree on the ray: same primitive or a tie at t.
::testing::AssertionResult agrees(const KdTree& kd, const BruteForce& bf, const Ray& r, const QueryOptions& qo = {}) {
  const Hit a = kd.closest_hit(r, qo), b = bf.closest_hit(r, qo);
  RayStats st;
  const Hit c = kd.closest_hit(r, qo, &st);
  if (a.valid() != b.valid() || c.prim != a.prim || kd.any_hit(r, qo) != b.valid())
    return ::testing::AssertionFailure() << "validity: kd " << a.valid() << " brute " << b.valid();
  if (a.valid() && a.prim != b.prim && std::fabs(a.t - b.t) > 1e-6f * std::max(1.0f, std::fabs(b.t)))
    return ::testing::AssertionFailure() << "kd prim " << a.prim << " t " << a.t << ", brute prim " << b.prim << " t "
                                         << b.t;
  return ::testing::AssertionSuccess();
}

}  // namespace

TEST(KdTree, OptionsAreValidated) {
  const Scene s = soup(1, 10, 0.1f);
  const auto throws_naming = [&](KdTreeOptions o, const char* what) {
    try {
      KdTree kd(s, o);
      ADD_FAILURE() << what << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  KdTreeOptions o;
  o.cost_traversal = 0.0f;
  throws_naming(o, "cost_traversal");
  o = {};
  o.cost_intersect = std::numeric_limits<float>::quiet_NaN();
  throws_naming(o, "cost_intersect");
  o = {};
  o.max_depth = -1;
  throws_naming(o, "max_depth");
  o.max_depth = 65;
  throws_naming(o, "max_depth");
  o = {};
  o.max_leaf_size = 0;
  throws_naming(o, "max_leaf_size");
  o = {};
  o.empty_bonus = 1.0f;
  throws_naming(o, "empty_bonus");
  o.empty_bonus = -0.1f;
  throws_naming(o, "empty_bonus");
  EXPECT_NO_THROW(validate(KdTreeOptions{}));
}

TEST(KdTree, EmptyInputMisses) {
  const KdTree kd(Scene{});
  EXPECT_EQ(kd.name(), "kdtree");
  EXPECT_EQ(kd.build_stats().node_count, 0u);
  EXPECT_FALSE(kd.closest_hit(Ray({0, 0, -1}, {0, 0, 1}), {}).valid());
  EXPECT_FALSE(kd.any_hit(Ray({0, 0, -1}, {0, 0, 1}), {}));
}

TEST(KdTree, OnePrimitive) {
  const Scene s{{{-1, -1, 2}, {1, -1, 2}, {0, 1, 2}}};
  const KdTree kd(s);
  EXPECT_EQ(kd.build_stats().node_count, 1u);
  const Hit h = kd.closest_hit(Ray({0, 0, 0}, {0, 0, 1}), {});
  ASSERT_TRUE(h.valid());
  EXPECT_EQ(h.prim, 0u);
  EXPECT_FLOAT_EQ(h.t, 2.0f);
  EXPECT_EQ(h.ng, glm::vec3(0, 0, 1));
}

// Named case "triangle 1 overlaps multiple nodes": a large triangle A lies
// in the far leaf and also overlaps the near leaf; the ray meets A first in
// the near leaf, at a distance beyond that leaf's exit, while a nearer
// triangle B waits in the far leaf. Ending the search on A's hit would
// return A; the answer must be B.
TEST(KdTree, TriangleOverlapsMultipleNodes) {
  Scene s;
  // A: in the slanted plane x = 2 + y, x in [-2, 3]; the ray (y = z = 0,
  // along +x) meets it at x = 2.
  s.push_back({{-2, -4, -1}, {3, 1, -1}, {2, 0, 3}});
  // B: small, in the plane x = 1, around the ray.
  s.push_back({{1, -0.2f, -0.2f}, {1, 0.2f, -0.2f}, {1, 0, 0.2f}});
  // Filler away from the ray, spread over x in [-3, 0], so the SAH cuts
  // the space in x between the filler and B.
  Rng rng{7};
  for (int i = 0; i < 200; ++i) {
    const glm::vec3 c = rng.in_box({-3, 1.5f, -2}, {-0.2f, 3, 2});
    s.push_back({c, c + glm::vec3(0.05f, 0, 0), c + glm::vec3(0, 0.05f, 0.05f)});
  }
  // Clamped bounds (no perfect splits) make A's reference in the near leaf
  // certain: with clipping the SAH isolates A's far part from the ray's
  // path in this small scene. The default options are checked below.
  KdTreeOptions o;
  o.cost_intersect = 20.0f;  // split eagerly
  o.max_leaf_size = 1;
  o.perfect_splits = false;
  const KdTree kd(s, o);
  const Ray ray({-5, 0, 0}, {1, 0, 0});
  VisitTrace trace;
  RayStats st;
  const Hit h = kd.closest_hit(ray, {}, &st, &trace);
  ASSERT_TRUE(h.valid());
  EXPECT_EQ(h.prim, 1u);
  EXPECT_FLOAT_EQ(h.t, 6.0f);
  // The scenario really happened: A was hit in a leaf whose exit lies
  // before A's hit, and the search went on.
  bool a_hit_beyond_leaf = false;
  float leaf_exit = kInfinity;
  for (const VisitStep& step : trace.steps) {
    if (step.kind == VisitStep::Kind::node_entered && kd.nodes()[step.id].is_leaf()) leaf_exit = step.t_exit;
    if (step.kind == VisitStep::Kind::prim_hit && step.id == 0u && step.t_entry > leaf_exit) a_hit_beyond_leaf = true;
  }
  EXPECT_TRUE(a_hit_beyond_leaf) << "tree did not put A in a leaf the ray leaves before A's hit";
  // Mailboxed: A is tested once although it lies in several leaves.
  EXPECT_EQ(st.repeated_prim_tests, 0u);
  const BruteForce bf(s);
  EXPECT_TRUE(agrees(kd, bf, ray));
  KdTreeOptions no_mb = o;
  no_mb.mailboxing = false;
  const KdTree kd2(s, no_mb);
  EXPECT_EQ(kd2.closest_hit(ray, {}).prim, 1u);
  EXPECT_EQ(KdTree(s).closest_hit(ray, {}).prim, 1u);
}

TEST(KdTree, MailboxingSavesRepeatedTestsOfStraddlingTriangles) {
  // Long thin triangles crossing the whole scene, over small clutter: every
  // long one lies in many leaves.
  Scene s = soup(3, 400, 0.05f);
  for (int i = 0; i < 8; ++i) {
    const float y = -0.9f + 0.25f * static_cast<float>(i);
    s.push_back({{-1, y, -1}, {1, y + 0.01f, 1}, {1, y + 0.02f, -1}});
  }
  KdTreeOptions on, off;
  off.mailboxing = false;
  const KdTree a(s, on), b(s, off);
  RayStats sa, sb;
  Rng rng{4};
  for (int i = 0; i < 2000; ++i) {
    const Ray r{glm::vec3(-3, 0, 0) + 0.3f * rng.unit(), glm::vec3{1, rng.range(-0.3f, 0.3f), rng.range(-0.3f, 0.3f)}};
    const Hit ha = a.closest_hit(r, {}, &sa), hb = b.closest_hit(r, {}, &sb);
    ASSERT_EQ(ha.prim, hb.prim);
  }
  EXPECT_GT(sb.repeated_prim_tests, 0u) << "without mailboxing straddling triangles are retested";
  EXPECT_LT(sa.repeated_prim_tests, sb.repeated_prim_tests / 4);
  EXPECT_LT(sa.prim_tests, sb.prim_tests);
  EXPECT_EQ(sb.prim_tests - sb.repeated_prim_tests, sa.prim_tests - sa.repeated_prim_tests)
      << "both test the same distinct primitives";
}

// Named case: rays lying in a split plane (a ±0 direction component on the
// split axis, the origin exactly on the plane). Both sides must be searched:
// triangles touching the plane from either side can be hit.
TEST(KdTree, RaysLyingInSplitPlanes) {
  const Scene s = lattice();
  const KdTree kd(s);
  const BruteForce bf(s);
  Rng rng{11};
  int checked = 0, hits = 0;
  for (const NodeInfo& n : walk(kd)) {
    const KdNode& node = kd.nodes()[n.index];
    if (node.is_leaf()) continue;
    const int a = node.axis();
    for (int k = 0; k < 40; ++k) {
      glm::vec3 o = rng.in_box(n.box.lo - 0.5f, n.box.hi + 0.5f);
      o[a] = node.split();
      glm::vec3 d = rng.unit();
      d[a] = (k & 1) ? 0.0f : -0.0f;
      if (k % 4 < 2) {  // axis-aligned within the plane
        const int b = (a + 1 + (k / 4) % 2) % 3;
        for (int c = 0; c < 3; ++c)
          if (c != a) d[c] = c == b ? (k % 8 < 4 ? 1.0f : -1.0f) : 0.0f;
      }
      const Ray r(o, d);
      EXPECT_TRUE(agrees(kd, bf, r)) << "split axis " << a << " at " << node.split();
      ++checked;
      hits += bf.closest_hit(r, {}).valid();
    }
  }
  EXPECT_GT(checked, 100);
  EXPECT_GT(hits, checked / 4);
}

// Named case: the split plane crossed exactly at tmin or at tmax (the
// segment starts or ends on the plane), including a triangle lying in the
// plane there.
TEST(KdTree, SplitDistanceEqualToTminOrTmax) {
  const Scene s = lattice();
  const KdTree kd(s);
  const BruteForce bf(s);
  Rng rng{12};
  int checked = 0, hits = 0;
  for (const NodeInfo& n : walk(kd)) {
    const KdNode& node = kd.nodes()[n.index];
    if (node.is_leaf()) continue;
    const int a = node.axis();
    const float p = node.split();  // a lattice coordinate: p ± 1 is exact
    for (int k = 0; k < 16; ++k) {
      glm::vec3 o = rng.in_box(n.box.lo, n.box.hi);
      glm::vec3 d(0.0f);
      d[a] = (k & 1) ? 1.0f : -1.0f;  // along the split axis, ±0 elsewhere
      if (k & 4) d[(a + 1) % 3] = 0.25f;
      o[a] = p - d[a];  // the plane is crossed at t = 1 exactly
      Ray r(o, d);
      if (k & 2)
        r.tmin = 1.0f;  // segment starts on the plane
      else
        r.tmax = 1.0f;  // segment ends on the plane
      EXPECT_TRUE(agrees(kd, bf, r)) << "axis " << a << " split " << p << " k " << k;
      ++checked;
      hits += bf.closest_hit(r, {}).valid();
    }
  }
  EXPECT_GT(checked, 50);
  EXPECT_GT(hits, 0);
  // A wall in the plane x = 1 hit exactly at tmax and exactly at tmin.
  const Ray to_wall({0.5f, 0.5f, 0.5f}, {1, 0, 0}, 0.0f, 0.5f);
  const Hit h = kd.closest_hit(to_wall, {});
  ASSERT_TRUE(h.valid());
  EXPECT_EQ(h.t, 0.5f);
  const Ray from_wall({0.5f, 0.5f, 0.5f}, {1, 0, 0}, 0.5f, 10.0f);
  EXPECT_EQ(kd.closest_hit(from_wall, {}).t, 0.5f);
}

TEST(KdTree, EveryTriangleReferencedWhereItOverlaps) {
  const Scene s = soup(5, 600, 0.2f);
  const KdTree kd(s);
  std::vector<int> refs(s.size(), 0);
  for (const NodeInfo& n : walk(kd)) {
    const KdNode& node = kd.nodes()[n.index];
    if (!node.is_leaf()) {
      EXPECT_GT(node.split(), n.box.lo[node.axis()]);
      EXPECT_LT(node.split(), n.box.hi[node.axis()]);
      continue;
    }
    std::vector<bool> in_leaf(s.size(), false);
    for (std::uint32_t k = 0; k < node.prim_count(); ++k) {
      const std::uint32_t id = kd.prim_refs()[node.prim_offset() + k];
      in_leaf[id] = true;
      ++refs[id];
    }
    // Conservative and exact up to the clipping's rounding: a triangle that
    // clearly overlaps the leaf's cell is in the leaf; one in the leaf
    // overlaps the cell grown by a hair.
    // (Touching only at the boundary is allowed either way: a triangle
    // whose extent ends on the split plane goes to one side only.)
    const glm::vec3 hair = 1e-5f * n.box.extent() + 1e-6f * (glm::abs(n.box.lo) + glm::abs(n.box.hi) + 1.0f);
    for (std::size_t i = 0; i < s.size(); ++i) {
      if (!in_leaf[i] && triangle_box_overlap(s[i], {n.box.lo + hair, n.box.hi - hair}))
        ADD_FAILURE() << "triangle " << i << " overlaps leaf " << n.index << " but is not in it";
      if (in_leaf[i] && !triangle_box_overlap(s[i], {n.box.lo - hair, n.box.hi + hair}))
        ADD_FAILURE() << "triangle " << i << " is in leaf " << n.index << " without overlapping it";
    }
  }
  for (std::size_t i = 0; i < s.size(); ++i) EXPECT_GT(refs[i], 0) << "triangle " << i << " in no leaf";
}

TEST(KdTree, StatsAndSahRecomputedIndependently) {
  const Scene s = soup(6, 1000, 0.1f);
  KdTreeOptions o;
  const KdTree kd(s, o);
  const BuildStats& st = kd.build_stats();
  double sah = 0.0, refs = 0.0, depth_sum = 0.0;
  std::uint64_t leaves = 0;
  std::uint32_t deepest = 0;
  const std::vector<NodeInfo> nodes = walk(kd);
  for (const NodeInfo& n : nodes) {
    const KdNode& node = kd.nodes()[n.index];
    if (node.is_leaf()) {
      sah += o.cost_intersect * node.prim_count() * n.box.half_area();
      refs += node.prim_count();
      ++leaves;
      depth_sum += n.depth;
      deepest = std::max<std::uint32_t>(deepest, n.depth);
    } else {
      sah += o.cost_traversal * n.box.half_area();
    }
  }
  EXPECT_EQ(nodes.size(), st.node_count) << "every node reachable exactly once";
  EXPECT_EQ(leaves, st.leaf_count);
  EXPECT_EQ(deepest, st.max_depth);
  EXPECT_NEAR(st.avg_leaf_depth, depth_sum / leaves, 1e-9);
  EXPECT_NEAR(st.sah_cost, sah / kd.bounds().half_area(), 1e-6 * st.sah_cost);
  EXPECT_EQ(st.extra.at("references"), refs);
  // Nodes, references and the triangles it copies (36 bytes each).
  EXPECT_EQ(st.memory_bytes, st.node_count * 8 + static_cast<std::uint64_t>(refs) * 4 + s.size() * 36);
  EXPECT_EQ(st.extra.at("max_depth_limit"), std::lround(8 + 1.3 * std::log2(1000.0)));
  EXPECT_LE(st.max_depth, static_cast<std::uint32_t>(st.extra.at("max_depth_limit")));
  EXPECT_LT(st.sah_cost, o.cost_intersect * 1000.0 / 10.0) << "the SAH tree is far better than one leaf";
  EXPECT_GE(st.build_ms, 0.0);
}

TEST(KdTree, PerfectSplitsReduceReferences) {
  // Walls in the planes x - y = c, diagonal to every split plane: their
  // bounds cover the whole square, their clipped parts a thin diagonal band.
  Scene s;
  for (int i = 0; i < 21; ++i) {
    const float c = -1.0f + 0.1f * static_cast<float>(i);
    quad(s, {c - 1, -1, -1}, {c + 1, 1, -1}, {c + 1, 1, 1}, {c - 1, -1, 1});
  }
  KdTreeOptions clamped;
  clamped.perfect_splits = false;
  const KdTree perfect(s), bounds_only(s, clamped);
  EXPECT_LT(perfect.build_stats().sah_cost, bounds_only.build_stats().sah_cost);  // 54.5 vs 61.3
  const BruteForce bf(s);
  Rng rng{8};
  for (int i = 0; i < 500; ++i) {
    const Ray r{glm::vec3(0, 0, -3) + 0.5f * rng.unit(), glm::vec3{rng.range(-0.5f, 0.5f), rng.range(-0.5f, 0.5f), 1}};
    EXPECT_TRUE(agrees(perfect, bf, r));
    EXPECT_TRUE(agrees(bounds_only, bf, r));
  }
}

TEST(KdTree, DegenerateInputsTerminate) {
  // All centroids equal.
  Scene same;
  Rng rng{9};
  for (int i = 0; i < 500; ++i) {
    const glm::vec3 da = rng.unit();
    const glm::vec3 a = da * rng.range(0.1f, 1.0f);
    const glm::vec3 db = rng.unit();
    const glm::vec3 b = db * rng.range(0.1f, 1.0f);
    same.push_back({a, b, -a - b});
  }
  // Duplicates, a flat wall, point triangles, one triangle repeated.
  const Scene dup(1000, Triangle{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  Scene wall;
  for (int i = 0; i < 30; ++i)
    for (int j = 0; j < 30; ++j)
      quad(wall, {i * 0.1f, j * 0.1f, 2}, {i * 0.1f + 0.1f, j * 0.1f, 2}, {i * 0.1f + 0.1f, j * 0.1f + 0.1f, 2},
           {i * 0.1f, j * 0.1f + 0.1f, 2});
  const Scene points(300, Triangle{{1, 1, 1}, {1, 1, 1}, {1, 1, 1}});
  for (const Scene* s : std::vector<const Scene*>{&same, &dup, &wall, &points}) {
    const KdTree kd(*s);
    EXPECT_LE(kd.build_stats().max_depth, 64u);
    EXPECT_LT(kd.build_stats().node_count, 40 * s->size() + 10);
    const BruteForce bf(*s);
    for (int i = 0; i < 300; ++i) {
      const Ray r{glm::vec3(0.5f, 0.5f, -3) + rng.unit(), glm::vec3{rng.range(-0.3f, 0.3f), rng.range(-0.3f, 0.3f), 1}};
      EXPECT_TRUE(agrees(kd, bf, r));
    }
  }
  // The flat wall has zero extent in z: no split on z, a good tree in x, y.
  const KdTree kw(wall);
  EXPECT_GT(kw.build_stats().leaf_count, 100u);
  // Duplicates cannot be separated: one leaf.
  EXPECT_EQ(KdTree(dup).build_stats().leaf_count, 1u);
}

TEST(KdTree, NonFiniteTrianglesAreLeftOut) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  Scene s = soup(10, 50, 0.2f);
  s.push_back({{nan, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  s.push_back({{kInfinity, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  const KdTree kd(s);
  for (std::uint32_t id : kd.prim_refs()) EXPECT_LT(id, 50u);
  EXPECT_TRUE(std::isfinite(kd.bounds().half_area()));
  const BruteForce bf(s);
  Rng rng{10};
  for (int i = 0; i < 200; ++i) EXPECT_TRUE(agrees(kd, bf, Ray(glm::vec3(0, 0, -3), rng.unit())));
}

TEST(KdTree, UnorderedTraversalSameAnswerMoreWork) {
  const Scene s = soup(12, 2000, 0.05f);
  const KdTree kd(s);
  QueryOptions unordered;
  unordered.ordered = false;
  RayStats so, su;
  Rng rng{13};
  for (int i = 0; i < 1000; ++i) {
    const Ray r{glm::vec3(0, 0, 0) + 3.0f * rng.unit(), rng.unit()};
    const Hit a = kd.closest_hit(r, {}, &so), b = kd.closest_hit(r, unordered, &su);
    ASSERT_EQ(a.prim, b.prim);
  }
  EXPECT_GT(su.nodes_visited, so.nodes_visited);
  EXPECT_GT(su.prim_tests, so.prim_tests);
  EXPECT_GT(so.nodes_culled + su.nodes_culled, 0u);
}

TEST(KdTree, TraceMatchesStats) {
  const Scene s = soup(14, 500, 0.1f);
  const KdTree kd(s);
  const Ray r({-3, 0.1f, 0.05f}, {1, 0, 0});
  RayStats st;
  VisitTrace tr;
  const Hit h = kd.closest_hit(r, {}, &st, &tr);
  std::uint32_t entered = 0, tests = 0;
  for (const VisitStep& step : tr.steps) {
    entered += step.kind == VisitStep::Kind::node_entered;
    tests += step.kind == VisitStep::Kind::prim_hit || step.kind == VisitStep::Kind::prim_miss;
  }
  EXPECT_EQ(entered, st.nodes_visited);
  EXPECT_EQ(tests, st.prim_tests);
  EXPECT_EQ(st.box_tests, 1u);
  EXPECT_EQ(h.prim, kd.closest_hit(r, {}).prim);
}

TEST(KdTree, ProgressAndCancellation) {
  const Scene s = soup(15, 3000, 0.05f);
  double last = 0.0;
  int calls = 0;
  const KdTree kd(s, {}, [&](double f) {
    EXPECT_GE(f, last);
    EXPECT_LE(f, 1.0);
    last = f;
    ++calls;
    return true;
  });
  EXPECT_GT(calls, 5);
  EXPECT_DOUBLE_EQ(last, 1.0);
  int seen = 0;
  EXPECT_THROW(KdTree(s, {}, [&](double) { return ++seen < 3; }), BuildCancelled);
  EXPECT_EQ(seen, 3);
}

// A scene large enough for the parallel build (16,384 primitives or more):
// random triangles and an axis-aligned subdivided cube (planar events, split
// planes through vertices) give the same node array, references and figures
// on any thread count as on one.
TEST(KdTree, SameTreeOnAnyThreadCount) {
  Scene s = soup(7, 30000, 0.03f);
  const Scene cube = subdivided_cube(glm::vec3(-0.4f), 0.8f, 20);
  s.insert(s.end(), cube.begin(), cube.end());
  ASSERT_GE(s.size(), 16384u);
  KdTreeOptions o;
  o.threads = 1;
  const KdTree one(s, o);
  for (unsigned t : {2u, 3u, 5u}) {
    o.threads = t;
    EXPECT_TRUE(same_tree(KdTree(s, o), one)) << t << " threads";
  }
  EXPECT_GT(one.nodes().size(), 1000u);
}

// The parallel build reports progress in order, from whichever thread, and
// stops on all threads at the first refusal.
TEST(KdTree, ParallelBuildProgressAndCancellation) {
  KdTreeOptions o;
  o.threads = 2;
  check_parallel_progress_and_cancellation<KdTree>(soup(16, 40000, 0.03f), o);
}
}  // namespace unity_test_kdtree
