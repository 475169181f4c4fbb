// Triangle-box overlap (core/geometry/tri_box_overlap.h): named touching and
// degenerate cases, and random cases against two independent references:
// sampling points on the triangle (any sample inside the box proves
// overlap) and clipping the triangle by the box in double (an empty clip
// against a slightly grown box proves separation).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "core/geometry/tri_box_overlap.h"
#include "tests/core/spatial_test_scenes.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_tri_box_overlap {

using namespace accelviz;
using test_scenes::Rng;

namespace {

const Aabb kUnit{{0, 0, 0}, {1, 1, 1}};

// Reference: is the triangle's clipped polygon against [lo, hi] non-empty?
// Plain Sutherland-Hodgman in long double, written independently of the
// library's clipper.
bool clip_nonempty(const Triangle& t, glm::dvec3 lo, glm::dvec3 hi) {
  using V = std::array<long double, 3>;
  std::vector<V> poly = {{t.v0.x, t.v0.y, t.v0.z}, {t.v1.x, t.v1.y, t.v1.z}, {t.v2.x, t.v2.y, t.v2.z}};
  for (int a = 0; a < 3; ++a)
    for (int s = 0; s < 2; ++s) {
      const long double c = s == 0 ? lo[a] : hi[a];
      const auto in = [&](const V& p) { return s == 0 ? p[a] >= c : p[a] <= c; };
      std::vector<V> out;
      for (std::size_t i = 0; i < poly.size(); ++i) {
        const V& p = poly[i];
        const V& q = poly[(i + 1) % poly.size()];
        if (in(p)) out.push_back(p);
        if (in(p) != in(q)) {
          const long double u = (c - p[a]) / (q[a] - p[a]);
          V r;
          for (int k = 0; k < 3; ++k) r[k] = p[k] + u * (q[k] - p[k]);
          r[a] = c;
          out.push_back(r);
        }
      }
      poly = out;
      if (poly.empty()) return false;
    }
  return true;
}

// Reference: does any of a dense set of samples (vertices, edge points,
// interior barycentrics) lie strictly inside the box shrunk by `margin`?
bool sample_inside(const Triangle& t, const Aabb& b, float margin) {
  const int n = 40;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n - i; ++j) {
      const double u = static_cast<double>(i) / n, v = static_cast<double>(j) / n;
      const glm::dvec3 p = (1.0 - u - v) * glm::dvec3(t.v0) + u * glm::dvec3(t.v1) + v * glm::dvec3(t.v2);
      bool inside = true;
      for (int a = 0; a < 3; ++a) inside = inside && p[a] > b.lo[a] + margin && p[a] < b.hi[a] - margin;
      if (inside) return true;
    }
  return false;
}

}  // namespace

TEST(TriBoxOverlap, TriangleInsideAndFarAway) {
  EXPECT_TRUE(triangle_box_overlap({{0.2f, 0.2f, 0.5f}, {0.8f, 0.2f, 0.5f}, {0.5f, 0.8f, 0.5f}}, kUnit));
  EXPECT_FALSE(triangle_box_overlap({{5, 5, 5}, {6, 5, 5}, {5, 6, 5}}, kUnit));
}

TEST(TriBoxOverlap, BoxInsideBigTriangle) {
  // No vertex in the box, the box pierced by the triangle's interior.
  EXPECT_TRUE(triangle_box_overlap({{-10, -10, 0.5f}, {10, -10, 0.5f}, {0, 10, 0.5f}}, kUnit));
  // Same plane shifted just off the box: the triangle normal separates.
  EXPECT_FALSE(triangle_box_overlap({{-10, -10, 1.001f}, {10, -10, 1.001f}, {0, 10, 1.001f}}, kUnit));
}

TEST(TriBoxOverlap, TouchingCountsAsOverlap) {
  // A vertex exactly on the box's corner.
  EXPECT_TRUE(triangle_box_overlap({{1, 1, 1}, {2, 1, 1}, {1, 2, 1.5f}}, kUnit));
  // An edge lying along a box edge, triangle outside.
  EXPECT_TRUE(triangle_box_overlap({{0, 0, 0}, {1, 0, 0}, {0.5f, -1, -1}}, kUnit));
  // Lying in the face plane z = 1.
  EXPECT_TRUE(triangle_box_overlap({{0.2f, 0.2f, 1}, {0.8f, 0.2f, 1}, {0.5f, 0.8f, 1}}, kUnit));
  // Lying in the face plane, partly beyond the face.
  EXPECT_TRUE(triangle_box_overlap({{-1, -1, 1}, {3, -1, 1}, {-1, 3, 1}}, kUnit));
  // Touching the face z = 1 with one vertex from outside.
  EXPECT_TRUE(triangle_box_overlap({{0.5f, 0.5f, 1}, {0.5f, 0.5f, 2}, {0.7f, 0.6f, 2}}, kUnit));
  // The same, one float step away.
  const float above = std::nextafter(1.0f, 2.0f);
  EXPECT_FALSE(triangle_box_overlap({{0.5f, 0.5f, above}, {0.5f, 0.5f, 2}, {0.7f, 0.6f, 2}}, kUnit));
}

TEST(TriBoxOverlap, BoundsOverlapButEdgeAxisSeparates) {
  // In the plane z = 0.5, which cuts the box, on the far side of the line
  // x + y = 2.05: the bounds overlap the box, the normal does not separate,
  // the cross product of z with the edge v0v1 does.
  EXPECT_FALSE(triangle_box_overlap({{2.05f, 0, 0.5f}, {0, 2.05f, 0.5f}, {3, 3, 0.5f}}, kUnit));
  // A triangle in the plane x + y = 2.5: its bounds contain the box's
  // corner, its normal separates.
  EXPECT_FALSE(triangle_box_overlap({{2.5f, 0, -1}, {0, 2.5f, -1}, {1.25f, 1.25f, 3}}, kUnit));
  // A needle segment passing just beyond the box edge (x=1, y=1): only an
  // edge cross-product axis separates it.
  EXPECT_FALSE(triangle_box_overlap({{2.05f, 0, 0.5f}, {0, 2.05f, 0.5f}, {1.025f, 1.025f, 0.5f}}, kUnit));
  EXPECT_TRUE(triangle_box_overlap({{1.95f, 0, 0.5f}, {0, 1.95f, 0.5f}, {0.975f, 0.975f, 0.5f}}, kUnit));
}

TEST(TriBoxOverlap, DegenerateTriangles) {
  // A point.
  EXPECT_TRUE(triangle_box_overlap({{0.5f, 0.5f, 0.5f}, {0.5f, 0.5f, 0.5f}, {0.5f, 0.5f, 0.5f}}, kUnit));
  EXPECT_FALSE(triangle_box_overlap({{1.5f, 0.5f, 0.5f}, {1.5f, 0.5f, 0.5f}, {1.5f, 0.5f, 0.5f}}, kUnit));
  // A point on a face.
  EXPECT_TRUE(triangle_box_overlap({{1, 0.5f, 0.5f}, {1, 0.5f, 0.5f}, {1, 0.5f, 0.5f}}, kUnit));
  // A segment (collinear vertices) through the box with both ends outside.
  EXPECT_TRUE(triangle_box_overlap({{-1, -1, -1}, {2, 2, 2}, {0.5f, 0.5f, 0.5f}}, kUnit));
  // A segment passing the corner (1,1,·) at distance 0.05·sqrt(2)/2: only
  // the cross-product axes separate it.
  EXPECT_FALSE(triangle_box_overlap({{2.05f, 0, 0.5f}, {0, 2.05f, 0.5f}, {0, 2.05f, 0.5f}}, kUnit));
  // Two coincident vertices (a segment) touching the box at its end.
  EXPECT_TRUE(triangle_box_overlap({{1, 1, 1}, {3, 3, 3}, {3, 3, 3}}, kUnit));
  // A needle whose float normal is rounding noise must not be separated by it.
  const Triangle needle{{-1.0f, 0.3f, 0.3f}, {2.0f, 0.3000001f, 0.3f}, {0.5f, 0.30000005f, 0.3f}};
  EXPECT_TRUE(triangle_box_overlap(needle, kUnit));
}

TEST(TriBoxOverlap, FlatAndEmptyBoxes) {
  const Aabb flat{{0, 0, 0.5f}, {1, 1, 0.5f}};  // zero thickness
  EXPECT_TRUE(triangle_box_overlap({{0.5f, 0.5f, 0}, {0.6f, 0.5f, 1}, {0.5f, 0.6f, 1}}, flat));
  EXPECT_FALSE(triangle_box_overlap({{0.5f, 0.5f, 0.6f}, {0.6f, 0.5f, 1}, {0.5f, 0.6f, 1}}, flat));
  const Aabb point = Aabb::of_point({0.25f, 0.25f, 0});
  EXPECT_TRUE(triangle_box_overlap({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, point));
  EXPECT_FALSE(triangle_box_overlap({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, Aabb::empty()));
}

TEST(TriBoxOverlap, NonFiniteVerticesNeverOverlap) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  EXPECT_FALSE(triangle_box_overlap({{nan, 0, 0}, {1, 0, 0}, {0, 1, 0}}, kUnit));
  EXPECT_FALSE(triangle_box_overlap({{kInfinity, 0, 0}, {1, 0, 0}, {0, 1, 0}}, kUnit));
  EXPECT_TRUE(clipped_triangle_bounds({{nan, 0, 0}, {1, 0, 0}, {0, 1, 0}}, kUnit).is_empty());
}

TEST(TriBoxOverlap, RandomAgainstSamplingAndClipping) {
  Rng rng{12345};
  int overlaps = 0, separations = 0, checked_by_sampling = 0;
  for (int it = 0; it < 20000; ++it) {
    const glm::vec3 c = rng.vec(-1, 1);
    const glm::vec3 h = rng.vec(0.01f, 0.5f);
    const Aabb box{c - h, c + h};
    // Triangles of all scales around the box: small, box-sized, huge; some
    // degenerate (a repeated vertex or collinear).
    const float scale = it % 3 == 0 ? 0.1f : (it % 3 == 1 ? 1.0f : 5.0f);
    Triangle t{c + rng.vec(-scale, scale), c + rng.vec(-scale, scale), c + rng.vec(-scale, scale)};
    if (it % 17 == 0) t.v2 = t.v1;
    if (it % 19 == 0) t.v2 = 0.5f * (t.v0 + t.v1);
    const bool got = triangle_box_overlap(t, box);
    const double d = 1e-5 * std::max(1.0, static_cast<double>(scale));
    const glm::dvec3 lo(box.lo), hi(box.hi);
    if (sample_inside(t, box, 0.0f)) {
      ++checked_by_sampling;
      EXPECT_TRUE(got) << "sample inside but no overlap, case " << it;
    }
    if (clip_nonempty(t, lo + d, hi - d)) {
      EXPECT_TRUE(got) << "clip of shrunk box non-empty, case " << it;
    }
    if (!clip_nonempty(t, lo - d, hi + d)) {
      EXPECT_FALSE(got) << "clip of grown box empty, case " << it;
    }
    (got ? overlaps : separations) += 1;
  }
  // Both outcomes must be well represented for the check to mean anything.
  EXPECT_GT(overlaps, 3000);
  EXPECT_GT(separations, 3000);
  EXPECT_GT(checked_by_sampling, 1000);
}

TEST(TriBoxOverlap, RandomTouchingCases) {
  // Triangles built to touch the box exactly: a vertex on a face, corner or
  // edge of the box, the rest outside.
  Rng rng{777};
  for (int it = 0; it < 5000; ++it) {
    const Aabb box{{0, 0, 0}, {1, 1, 1}};
    glm::vec3 p = rng.vec(0, 1);
    const int a = it % 3;
    p[a] = 1.0f;                              // on the face x_a = 1
    if (it % 5 == 0) p[(a + 1) % 3] = 0.0f;   // on an edge
    if (it % 25 == 0) p[(a + 2) % 3] = 1.0f;  // on a corner
    glm::vec3 q = p + rng.vec(0.1f, 1.0f), r = p + rng.vec(0.1f, 1.0f);
    q[a] = std::max(q[a], 1.1f);
    r[a] = std::max(r[a], 1.1f);
    EXPECT_TRUE(triangle_box_overlap({p, q, r}, box)) << "case " << it;
    // Nudged a float step outward it must separate (by the box axis a).
    glm::vec3 p2 = p;
    p2[a] = std::nextafter(1.0f, 2.0f);
    EXPECT_FALSE(triangle_box_overlap({p2, q, r}, box)) << "case " << it;
  }
}

TEST(ClippedTriangleBounds, InsideTriangleKeepsItsBounds) {
  const Triangle t{{0.2f, 0.3f, 0.4f}, {0.5f, 0.6f, 0.7f}, {0.9f, 0.1f, 0.2f}};
  const Aabb b = clipped_triangle_bounds(t, kUnit);
  EXPECT_EQ(b.lo, t.bounds().lo);
  EXPECT_EQ(b.hi, t.bounds().hi);
}

TEST(ClippedTriangleBounds, DisjointGivesEmpty) {
  EXPECT_TRUE(clipped_triangle_bounds({{2, 2, 2}, {3, 2, 2}, {2, 3, 2}}, kUnit).is_empty());
  // Bounds overlap, triangle does not (cuts past the corner).
  EXPECT_TRUE(clipped_triangle_bounds({{2.5f, 0, 0.5f}, {0, 2.5f, 0.5f}, {2.5f, 2.5f, 0.5f}}, kUnit).is_empty());
}

TEST(ClippedTriangleBounds, PlanarTriangleStaysPlanar) {
  // A triangle in the plane z = 0.25 crossing the box: clipped bounds keep
  // lo.z == hi.z == 0.25 exactly (the K-D tree's planar events rely on it).
  const Aabb b = clipped_triangle_bounds({{-1, -1, 0.25f}, {3, -1, 0.25f}, {-1, 3, 0.25f}}, kUnit);
  EXPECT_EQ(b.lo.z, 0.25f);
  EXPECT_EQ(b.hi.z, 0.25f);
  EXPECT_EQ(b.lo.x, 0.0f);
  EXPECT_EQ(b.hi.x, 1.0f);
}

TEST(ClippedTriangleBounds, ClipsToTheTrianglePartInside) {
  // A right triangle with hypotenuse x + y = 1.5 clipped to the unit box:
  // the clipped part spans x, y in [0, 1], while a corner-cut triangle's
  // part is much smaller than box ∩ bounds.
  const Triangle t{{0, 0, 0.5f}, {1.5f, 0, 0.5f}, {0, 1.5f, 0.5f}};
  const Aabb b = clipped_triangle_bounds(t, kUnit);
  EXPECT_EQ(b.hi.x, 1.0f);
  const Triangle corner{{0.9f, 0.9f, 0.5f}, {2, 0.9f, 0.5f}, {0.9f, 2, 0.5f}};  // inside: only (0.9..1, 0.9..1)
  const Aabb c = clipped_triangle_bounds(corner, kUnit);
  ASSERT_FALSE(c.is_empty());
  EXPECT_LE(c.lo.x, 0.9f);
  EXPECT_GE(c.lo.x, 0.9f - 1e-6f);
  EXPECT_LE(c.lo.y, 0.9f);
  EXPECT_GE(c.lo.y, 0.9f - 1e-6f);
  EXPECT_EQ(c.hi.x, 1.0f);
  EXPECT_EQ(c.hi.y, 1.0f);
}

TEST(ClippedTriangleBounds, RandomContainsEverySampleInside) {
  Rng rng{99};
  for (int it = 0; it < 3000; ++it) {
    const glm::vec3 c = rng.vec(-1, 1);
    const glm::vec3 h = rng.vec(0.05f, 0.5f);
    const Aabb box{c - h, c + h};
    const Triangle t{c + rng.vec(-1, 1), c + rng.vec(-1, 1), c + rng.vec(-1, 1)};
    const Aabb b = clipped_triangle_bounds(t, box);
    if (!b.is_empty()) {
      EXPECT_TRUE(box.contains(b)) << "case " << it;
      EXPECT_TRUE(t.bounds().contains(b)) << "case " << it;
    }
    const int n = 24;
    for (int i = 0; i <= n; ++i)
      for (int j = 0; j <= n - i; ++j) {
        const float u = static_cast<float>(i) / n, v = static_cast<float>(j) / n;
        const glm::vec3 p = (1 - u - v) * t.v0 + u * t.v1 + v * t.v2;
        if (!box.contains(p)) continue;
        ASSERT_FALSE(b.is_empty()) << "case " << it;
        // Samples are rounded to float; allow that rounding.
        const glm::vec3 tol = 1e-6f * (glm::abs(p) + 1.0f);
        EXPECT_TRUE(glm::all(glm::lessThanEqual(b.lo - tol, p)) && glm::all(glm::lessThanEqual(p, b.hi + tol)))
            << "case " << it;
      }
  }
}
}  // namespace unity_test_tri_box_overlap
