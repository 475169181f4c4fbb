// Uniform grid (core/accel/grid): resolution rules, CSR invariants (every
// triangle in exactly the cells its padded exact overlap touches), and the
// 3D-DDA's named hard cases: rays starting inside and outside, through cell
// edges and corners exactly, along cell planes with ±0 components, a hit
// found beyond the current cell, flat bounds, degenerate inputs.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "core/accel/brute_force.h"
#include "core/accel/grid/grid.h"
#include "core/accel/kdtree/spatial_traversal.h"
#include "core/geometry/tri_box_overlap.h"
#include "tests/core/spatial_test_scenes.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_grid {

using namespace accelviz;
using namespace accelviz::test_scenes;

namespace {

using Scene = std::vector<Triangle>;

// Triangles with corners on the integer lattice of [0, 4]^3; with a 4^3
// grid the cell planes are the integers, so triangle edges and vertices lie
// on cell edges and corners.
Scene integer_lattice(std::uint64_t seed) {
  Rng rng{seed};
  Scene s;
  const auto lattice_point = [&] {
    return glm::vec3{std::floor(rng.range(0, 4.999f)), std::floor(rng.range(0, 4.999f)),
                     std::floor(rng.range(0, 4.999f))};
  };
  quad(s, {0, 0, 0}, {4, 0, 0}, {4, 4, 0}, {0, 4, 0});  // pin the bounds to [0, 4]^3
  quad(s, {0, 0, 4}, {4, 0, 4}, {4, 4, 4}, {0, 4, 4});
  for (int i = 0; i < 60; ++i) s.push_back({lattice_point(), lattice_point(), lattice_point()});
  return s;
}

::testing::AssertionResult agrees(const Accelerator& a, const BruteForce& bf, const Ray& r) {
  const QueryOptions qo;
  const Hit h = a.closest_hit(r, qo), b = bf.closest_hit(r, qo);
  RayStats st;
  const Hit hs = a.closest_hit(r, qo, &st);
  if (h.valid() != b.valid() || hs.prim != h.prim || a.any_hit(r, qo) != b.valid())
    return ::testing::AssertionFailure() << "validity: grid " << h.valid() << " brute " << b.valid();
  if (h.valid() && h.prim != b.prim && std::fabs(h.t - b.t) > 1e-6f * std::max(1.0f, std::fabs(b.t)))
    return ::testing::AssertionFailure() << "grid prim " << h.prim << " t " << h.t << ", brute prim " << b.prim << " t "
                                         << b.t;
  return ::testing::AssertionSuccess();
}

}  // namespace

TEST(Grid, OptionsAreValidated) {
  const Scene s = soup(1, 10, 0.1f);
  const auto throws_naming = [&](GridOptions o, const char* what) {
    try {
      Grid g(s, o);
      ADD_FAILURE() << what << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  GridOptions o;
  o.resolution = {0, 4, 4};
  throws_naming(o, "resolution");
  o.resolution = {-1, -1, -1};
  throws_naming(o, "resolution");
  o.resolution = {1024, 1024, 1024};
  throws_naming(o, "2^26");
  o = {};
  o.lambda = 0.0f;
  throws_naming(o, "lambda");
  o.lambda = std::numeric_limits<float>::infinity();
  throws_naming(o, "lambda");
  EXPECT_NO_THROW(validate(GridOptions{}));
}

TEST(Grid, AutomaticResolutionFollowsLambdaAndAspect) {
  const Aabb b{{0, 0, 0}, {4, 2, 1}};
  const std::array<int, 3> r = grid_resolution(b, 1000, GridOptions{});
  // n_i = extent_i · cbrt(3000 / 8) = extent_i · 7.21
  EXPECT_EQ(r[0], 29);
  EXPECT_EQ(r[1], 14);
  EXPECT_EQ(r[2], 7);
  GridOptions dense;
  dense.lambda = 24.0f;
  const std::array<int, 3> d = grid_resolution(b, 1000, dense);
  EXPECT_NEAR(static_cast<double>(d[0]) * d[1] * d[2], 24000.0, 2400.0);
  // Manual resolution is taken as is.
  GridOptions manual;
  manual.resolution = {3, 5, 7};
  EXPECT_EQ(grid_resolution(b, 1000, manual), (std::array<int, 3>{3, 5, 7}));
  // A cap on the cells however large lambda·N.
  GridOptions huge;
  huge.lambda = 1000.0f;
  const std::array<int, 3> h = grid_resolution(b, 10'000'000, huge);
  EXPECT_LE(static_cast<std::uint64_t>(h[0]) * h[1] * h[2], kGridMaxCells);
}

TEST(Grid, FlatBoundsGiveThatAxisOneCell) {
  // Zero extent in z: a 2D grid of about lambda·N cells.
  const Aabb flat{{0, 0, 5}, {2, 1, 5}};
  const std::array<int, 3> r = grid_resolution(flat, 600, GridOptions{});
  EXPECT_EQ(r[2], 1);
  EXPECT_NEAR(static_cast<double>(r[0]) * r[1], 1800.0, 200.0);
  EXPECT_NEAR(static_cast<double>(r[0]) / r[1], 2.0, 0.1);
  // A line (two flat axes) and a point.
  EXPECT_EQ(grid_resolution({{0, 0, 0}, {3, 0, 0}}, 100, GridOptions{}), (std::array<int, 3>{300, 1, 1}));
  EXPECT_EQ(grid_resolution({{1, 1, 1}, {1, 1, 1}}, 100, GridOptions{}), (std::array<int, 3>{1, 1, 1}));
  // A very thin slab: the thin axis gets one cell, the budget goes to the others.
  const std::array<int, 3> thin = grid_resolution({{0, 0, 0}, {1, 1, 1e-6f}}, 1000, GridOptions{});
  EXPECT_EQ(thin[2], 1);
  EXPECT_NEAR(static_cast<double>(thin[0]) * thin[1], 3000.0, 300.0);

  // And the grid over a flat wall works.
  Scene wall;
  for (int i = 0; i < 20; ++i)
    for (int j = 0; j < 10; ++j)
      quad(wall, {0.1f * i, 0.1f * j, 5}, {0.1f * i + 0.1f, 0.1f * j, 5}, {0.1f * i + 0.1f, 0.1f * j + 0.1f, 5},
           {0.1f * i, 0.1f * j + 0.1f, 5});
  const Grid g(wall);
  EXPECT_EQ(g.resolution()[2], 1);
  const BruteForce bf(wall);
  Rng rng{3};
  for (int i = 0; i < 2000; ++i) {
    const glm::vec3 o = rng.in_box({-1, -1, 3}, {3, 2, 7});
    const glm::vec3 d =
        i % 4 == 0 ? glm::vec3{rng.range(-1, 1), rng.range(-1, 1), -0.0f} : rng.in_box({0, 0, 5}, {2, 1, 5}) - o;
    ASSERT_TRUE(agrees(g, bf, Ray(o, d))) << i;
  }
  // A ray lying in the wall's plane (z = 5, direction z = ±0) grazes edges.
  for (int i = 0; i < 200; ++i)
    ASSERT_TRUE(agrees(
        g, bf,
        Ray{{rng.range(-1, 3), rng.range(-1, 2), 5}, {rng.range(-1, 1), rng.range(-1, 1), (i & 1) ? 0.0f : -0.0f}}));
}

TEST(Grid, CsrListsHoldExactlyTheOverlappingTriangles) {
  const Scene s = soup(2, 300, 0.3f);
  for (bool exact : {true, false}) {
    GridOptions o;
    o.exact_overlap = exact;
    o.resolution = {6, 5, 7};
    const Grid g(s, o);
    const auto start = g.cell_start();
    ASSERT_EQ(start.size(), 6u * 5u * 7u + 1u);
    EXPECT_EQ(start.front(), 0u);
    EXPECT_EQ(start.back(), g.refs().size());
    for (std::size_t c = 0; c + 1 < start.size(); ++c) ASSERT_LE(start[c], start[c + 1]);
    const float pad = spatial::cell_padding(g.bounds().lo, g.bounds().hi);
    std::size_t empty = 0;
    for (int z = 0; z < 7; ++z)
      for (int y = 0; y < 5; ++y)
        for (int x = 0; x < 6; ++x) {
          const std::size_t c = x + 6 * (y + 5 * z);
          std::vector<bool> listed(s.size(), false);
          for (std::uint32_t k = start[c]; k < start[c + 1]; ++k) {
            ASSERT_FALSE(listed[g.refs()[k]]) << "listed twice";
            listed[g.refs()[k]] = true;
            if (k > start[c]) {
              EXPECT_LT(g.refs()[k - 1], g.refs()[k]) << "lists are in ascending id order";
            }
          }
          empty += start[c] == start[c + 1];
          const Aabb cell = padded_box(g.cell_box(x, y, z), pad);
          for (std::size_t i = 0; i < s.size(); ++i) {
            const Aabb tb = s[i].bounds();
            const bool boxes = !Aabb::intersection(tb, cell).is_empty();
            const bool expected = exact ? triangle_box_overlap(s[i], cell) : boxes;
            // Exact: precisely the padded overlap. Bounds: every cell the
            // padded bounds reach (it may also list a cell the box touches
            // only through the floor's rounding, never miss one).
            if (exact) {
              EXPECT_EQ(listed[i], expected) << "cell " << c << " triangle " << i;
            } else if (expected) {
              EXPECT_TRUE(listed[i]) << "cell " << c << " triangle " << i;
            }
          }
        }
    EXPECT_EQ(g.build_stats().extra.at("empty_cells"), static_cast<double>(empty));
    EXPECT_EQ(g.build_stats().extra.at("references"), static_cast<double>(g.refs().size()));
    // The cells, the references and the triangles it copies (36 bytes each).
    EXPECT_EQ(g.build_stats().memory_bytes, (start.size() + g.refs().size()) * 4 + s.size() * 36);
    EXPECT_EQ(g.build_stats().node_count, 210u);
  }
  // Exact overlap lists fewer references than bounds overlap.
  GridOptions bounds;
  bounds.exact_overlap = false;
  EXPECT_LT(Grid(s).build_stats().extra.at("references"), Grid(s, bounds).build_stats().extra.at("references"));
}

TEST(Grid, RaysStartingInsideAndOutside) {
  const Scene s = soup(4, 400, 0.1f);
  const Grid g(s);
  const BruteForce bf(s);
  Rng rng{5};
  for (int i = 0; i < 3000; ++i) {
    const glm::vec3 o = i % 2 ? rng.in_box(glm::vec3(-1), glm::vec3(1)) : 4.0f * rng.unit();
    const glm::vec3 d = i % 2 ? rng.unit() : rng.in_box(glm::vec3(-1), glm::vec3(1)) - o;
    Ray r(o, d);
    if (i % 3 == 0) r.tmax = rng.range(0.1f, 2.0f);
    ASSERT_TRUE(agrees(g, bf, r)) << i;
  }
  // Pointing away from the grid, and a segment ending before it.
  EXPECT_FALSE(g.closest_hit(Ray({5, 5, 5}, {1, 1, 1}), {}).valid());
  EXPECT_FALSE(g.any_hit(Ray({5, 0, 0}, {-1, 0, 0}, 0.0f, 2.0f), {}));
}

// Named case: axis-aligned rays from far away (3e7 .. 1e25 scene sizes) find what brute force finds,
// at the same float t up to its rounding there. The float entry t there is rounded by whole units, which put the entry
// point and the first cell at the grid's far side: every such ray missed.
TEST(Grid, RaysFromFarAwayEnterAtTheRightCell) {
  const Scene s = soup(4, 400, 0.1f);
  GridOptions o;
  o.resolution = {8, 8, 8};
  const Grid g(s, o);
  const BruteForce bf(s);
  Rng rng{9};
  int hits = 0;
  // Exactly along an axis, and nearly (a lateral component of 1e-28 of the axial one: the entry
  // t's of the two faces then round equal, and the face was picked by them, the far one). From 1e16
  // on, o + t·d loses the entry coordinate even in double: the entry face's own coordinate is used.
  for (const float far : {3e7f, 1e9f, 1e12f, 1e16f, 1e20f, 1e25f})
    for (int i = 0; i < 200; ++i) {
      const glm::vec3 p = rng.in_box(glm::vec3(-1), glm::vec3(1));
      const int axis = i % 3;
      glm::vec3 origin = p, dir(0.0f);
      origin[axis] = (i % 2 ? far : -far);
      dir[axis] = (i % 2 ? -1.0f : 1.0f) * (i % 5 == 0 ? 1e-3f : 1.0f);
      if (i % 4 == 0) dir[(axis + 1) % 3] = 1e-28f * (i % 8 == 0 ? 1.0f : -1.0f);
      const Ray r(origin, dir);
      const Hit a = g.closest_hit(r, {}), b = bf.closest_hit(r, {});
      ASSERT_EQ(a.valid(), b.valid()) << far << " ray " << i;
      if (!b.valid()) continue;
      ++hits;
      // Within a few float steps of t there (2 at 3e7): which of two triangles that close float
      // cannot order is a near tie.
      EXPECT_NEAR(a.t, b.t, 4e-7 * b.t) << far << " ray " << i;
      EXPECT_TRUE(g.any_hit(r, {})) << far << " ray " << i;
    }
  EXPECT_GT(hits, 100) << "the rays must mostly hit for the check to mean anything";
}

// Named case: rays through cell edges and corners exactly, and along cell
// planes. On a 4^3 grid over [0, 4]^3 the cell planes are the integers;
// rays along the body diagonal pass through every cell corner on their way,
// rays in the plane x = 2 with a ±0 x component lie on a cell face.
TEST(Grid, RaysThroughCellEdgesAndCornersExactly) {
  const Scene s = integer_lattice(6);
  GridOptions o;
  o.resolution = {4, 4, 4};
  const Grid g(s, o);
  ASSERT_EQ(g.plane(0, 2), 2.0f);
  ASSERT_EQ(g.plane(2, 4), 4.0f);
  const BruteForce bf(s);
  int hits = 0, n = 0;
  for (int i = 0; i <= 4; ++i)
    for (int j = 0; j <= 4; ++j)
      for (const glm::vec3 d :
           {glm::vec3(1, 1, 1), glm::vec3(1, -1, 1), glm::vec3(-1, 1, 1), glm::vec3(1, 1, -1), glm::vec3(1, 1, 0),
            glm::vec3(1, -0.0f, 1), glm::vec3(0, 0, 1), glm::vec3(-0.0f, -0.0f, -1)}) {
        // Through lattice points: from outside, corners of cells all the way.
        const glm::vec3 p(static_cast<float>(i), static_cast<float>(j), 2.0f);
        for (const float back : {6.0f, 0.0f}) {
          const Ray r(p - back * d, d);
          EXPECT_TRUE(agrees(g, bf, r)) << "through (" << i << "," << j << ",2) d=(" << d.x << "," << d.y << "," << d.z
                                        << ")";
          hits += bf.closest_hit(r, {}).valid();
          ++n;
        }
      }
  EXPECT_GT(hits, n / 3);
  // Along cell faces: origin on x = 2 (or y = 3), x (y) direction ±0.
  Rng rng{7};
  for (int i = 0; i < 1000; ++i) {
    glm::vec3 o = rng.in_box(glm::vec3(-1), glm::vec3(5)), d = rng.unit();
    const int a = i % 3;
    o[a] = static_cast<float>(i % 5);
    d[a] = (i & 8) ? 0.0f : -0.0f;
    ASSERT_TRUE(agrees(g, bf, Ray(o, d))) << i;
  }
}

// Named case: a large triangle straddling many cells is hit in a later cell
// first tested from an earlier cell; a nearer small triangle lies in a cell
// in between. The far hit must not end the walk.
TEST(Grid, HitBeyondTheCurrentCellDoesNotEndTheWalk) {
  Scene s;
  s.push_back({{-2, -4, -1}, {3, 1, -1}, {2, 0, 3}});                // A: x = 2 + y, met at x = 2
  s.push_back({{1, -0.2f, -0.2f}, {1, 0.2f, -0.2f}, {1, 0, 0.2f}});  // B: x = 1
  GridOptions o;
  o.resolution = {10, 1, 10};  // one tall row in y: A lies in every cell of the ray's row
  const Grid g(s, o);
  const Ray ray({-5, 0, 0}, {1, 0, 0});
  VisitTrace tr;
  const Hit h = g.closest_hit(ray, {}, nullptr, &tr);
  ASSERT_TRUE(h.valid());
  EXPECT_EQ(h.prim, 1u);
  EXPECT_FLOAT_EQ(h.t, 6.0f);
  bool a_beyond = false;
  float exit = kInfinity;
  for (const VisitStep& st : tr.steps) {
    if (st.kind == VisitStep::Kind::node_entered) exit = st.t_exit;
    if (st.kind == VisitStep::Kind::prim_hit && st.id == 0u && st.t_entry > exit) a_beyond = true;
  }
  EXPECT_TRUE(a_beyond) << "A was not met beyond its cell first";
}

TEST(Grid, StatsMailboxingAndEmptyCells) {
  // Long triangles crossing many cells over sparse clutter.
  Scene s = soup(8, 100, 0.05f);
  for (int i = 0; i < 6; ++i) {
    const float y = -0.9f + 0.3f * static_cast<float>(i);
    s.push_back({{-1, y, -1}, {1, y + 0.01f, 1}, {1, y + 0.02f, -1}});
  }
  GridOptions on, off;
  off.mailboxing = false;
  const Grid a(s, on), b(s, off);
  RayStats sa, sb;
  Rng rng{9};
  for (int i = 0; i < 2000; ++i) {
    const Ray r{glm::vec3(-3, 0, 0) + 0.3f * rng.unit(), glm::vec3{1, rng.range(-0.3f, 0.3f), rng.range(-0.3f, 0.3f)}};
    ASSERT_EQ(a.closest_hit(r, {}, &sa).prim, b.closest_hit(r, {}, &sb).prim);
  }
  EXPECT_GT(sb.repeated_prim_tests, 0u);
  EXPECT_LT(sa.repeated_prim_tests, sb.repeated_prim_tests / 4);
  EXPECT_GT(sa.empty_cells, 0u);
  EXPECT_GT(sa.nodes_visited, sa.empty_cells);
  EXPECT_EQ(sa.box_tests, 2000u);
  // A ray through empty space only: every cell visited is empty.
  RayStats se;
  const Ray miss({-3, 1.5f, 1.5f}, {1, 0, 0});
  EXPECT_FALSE(a.closest_hit(miss, {}, &se).valid());
  EXPECT_EQ(se.prim_tests, 0u);
}

TEST(Grid, EmptyOneAndDegenerateInputs) {
  const Grid none(Scene{});
  EXPECT_EQ(none.name(), "grid");
  EXPECT_FALSE(none.closest_hit(Ray({0, 0, -1}, {0, 0, 1}), {}).valid());
  EXPECT_FALSE(none.any_hit(Ray({0, 0, -1}, {0, 0, 1}), {}));
  EXPECT_EQ(none.build_stats().node_count, 0u);
  EXPECT_EQ(none.build_stats().max_depth, 0u);

  const Scene one{{{-1, -1, 2}, {1, -1, 2}, {0, 1, 2}}};
  const Grid g1(one);
  const Hit h = g1.closest_hit(Ray({0, 0, 0}, {0, 0, 1}), {});
  ASSERT_TRUE(h.valid());
  EXPECT_FLOAT_EQ(h.t, 2.0f);
  // The cells lie one level below the bounds (depth 0), as the box views draw them.
  EXPECT_EQ(g1.build_stats().max_depth, 1u);
  EXPECT_EQ(g1.build_stats().avg_leaf_depth, 1.0);

  Rng rng{10};
  Scene same;  // all centroids equal
  for (int i = 0; i < 300; ++i) {
    const glm::vec3 a = rng.unit(), b = rng.unit();
    same.push_back({a, b, -a - b});
  }
  const Scene dup(500, Triangle{{0, 0, 0}, {1, 0, 0}, {0, 1, 0.5f}});
  const Scene points(100, Triangle{{1, 2, 3}, {1, 2, 3}, {1, 2, 3}});
  const float nan = std::numeric_limits<float>::quiet_NaN();
  Scene with_nan = soup(11, 50, 0.2f);
  with_nan.push_back({{nan, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  for (const Scene* s : std::vector<const Scene*>{&same, &dup, &points, &with_nan}) {
    const Grid g(*s);
    const BruteForce bf(*s);
    for (int i = 0; i < 300; ++i) {
      const glm::vec3 o = 3.0f * rng.unit();
      ASSERT_TRUE(agrees(g, bf, Ray(o, rng.in_box(glm::vec3(-1), glm::vec3(1)) - o)));
    }
  }
}

TEST(Grid, ProgressAndCancellation) {
  const Scene s = soup(12, 20000, 0.02f);
  double last = 0.0;
  int calls = 0;
  const Grid g(s, {}, [&](double f) {
    EXPECT_GE(f, last);
    last = f;
    ++calls;
    return true;
  });
  EXPECT_GT(calls, 3);
  EXPECT_DOUBLE_EQ(last, 1.0);
  EXPECT_THROW(Grid(s, {}, [](double f) { return f < 0.3; }), BuildCancelled);
}
}  // namespace unity_test_grid
