// Polygon triangulation (core/geometry/polygon.h): convex quads keep their
// fan, larger convex faces are split in halves, concave ones are ear-clipped inside their outline within a bounded
// number of steps.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <glm/geometric.hpp>
#include <vector>

#include "core/geometry/polygon.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace accelviz::unity_test_polygon {
namespace {

double shoelace(const std::vector<glm::vec3>& p) {
  double a = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const glm::vec3& u = p[i];
    const glm::vec3& v = p[(i + 1) % p.size()];
    a += static_cast<double>(u.x) * v.y - static_cast<double>(v.x) * u.y;
  }
  return 0.5 * a;
}

double covered(const std::vector<glm::vec3>& p, const std::vector<std::array<std::uint32_t, 3>>& tris) {
  double a = 0.0;
  for (const auto& [i, j, k] : tris) {
    const glm::vec3 n = glm::cross(p[j] - p[i], p[k] - p[i]);
    a += 0.5 * n.z;  // signed: a triangle of the wrong winding would subtract
  }
  return a;
}

TEST(Polygon, AConvexQuadKeepsItsFan) {
  const std::vector<glm::vec3> quad = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  const auto tris = triangulate_polygon(quad);
  ASSERT_EQ(tris.size(), 2u);
  EXPECT_EQ(tris[0], (std::array<std::uint32_t, 3>{0, 1, 2}));
  EXPECT_EQ(tris[1], (std::array<std::uint32_t, 3>{0, 2, 3}));
}

// A convex polygon of five or more corners is cut (0, t, 2t) and then by halves, not fanned: the
// hexagon's middle triangle and its three ears; a 4,000-gon tiled exactly once, in its winding,
// with no corner in more than a few triangles (the fan put corner 0 in all 3,998, each a sliver
// across the face) and a total edge length of a few dozen times the outline's (the fan's: n).
TEST(Polygon, ALargerConvexFaceIsSplitInHalvesNotFanned) {
  const std::vector<glm::vec3> hexagon = {{2, 0, 0}, {1, 2, 0}, {-1, 2, 0}, {-2, 0, 0}, {-1, -2, 0}, {1, -2, 0}};
  const std::vector<std::array<std::uint32_t, 3>> expected = {{0, 2, 4}, {0, 1, 2}, {2, 3, 4}, {4, 5, 0}};
  EXPECT_EQ(triangulate_polygon(hexagon), expected);

  const std::size_t n = 4000;  // more, and a circle stops being convex in float
  std::vector<glm::vec3> circle;
  for (std::size_t i = 0; i < n; ++i) {
    const double a = 6.283185307179586 * static_cast<double>(i) / n;
    circle.push_back({static_cast<float>(std::cos(a)), static_cast<float>(std::sin(a)), 0.0f});
  }
  const auto tris = triangulate_polygon(circle);
  ASSERT_EQ(tris.size(), n - 2);
  EXPECT_NEAR(covered(circle, tris), shoelace(circle), 1e-9 * n);
  std::vector<int> degree(n, 0);
  double edges = 0.0;
  for (const auto& [i, j, k] : tris) {
    EXPECT_GT(glm::cross(circle[j] - circle[i], circle[k] - circle[i]).z, 0.0f);
    ++degree[i];
    ++degree[j];
    ++degree[k];
    edges +=
        glm::length(circle[j] - circle[i]) + glm::length(circle[k] - circle[j]) + glm::length(circle[i] - circle[k]);
  }
  EXPECT_EQ(std::count(degree.begin(), degree.end(), 0), 0);
  EXPECT_LE(*std::max_element(degree.begin(), degree.end()), 40);
  EXPECT_LT(edges, 40.0 * 6.283185307179586);
}

TEST(Polygon, AConcaveCombIsCoveredExactlyOnceInItsOwnWinding) {
  // A comb of 126 teeth (254 corners, the most an OBJ face reaches the triangulation with): every
  // triangle inside, together exactly the comb's area, in n - 2 triangles.
  std::vector<glm::vec3> comb;
  for (int k = 0; k < 126; ++k) {
    comb.push_back({2.0f * k, 1.0f, 0.0f});
    comb.push_back({2.0f * k + 1.0f, 0.2f, 0.0f});
  }
  comb.push_back({comb.back().x, -1.0f, 0.0f});
  comb.push_back({0.0f, -1.0f, 0.0f});
  std::vector<glm::vec3> ccw(comb.rbegin(), comb.rend());  // counter-clockwise, area positive
  const auto tris = triangulate_polygon(ccw);
  EXPECT_EQ(tris.size(), ccw.size() - 2);
  EXPECT_NEAR(covered(ccw, tris), shoelace(ccw), 1e-6 * std::abs(shoelace(ccw)));
  for (const auto& [i, j, k] : tris) EXPECT_GE(glm::cross(ccw[j] - ccw[i], ccw[k] - ccw[i]).z, 0.0f);
  // The same outline the other way round: the triangles wind with it.
  const auto cw = triangulate_polygon(comb);
  EXPECT_NEAR(covered(comb, cw), shoelace(comb), 1e-6 * std::abs(shoelace(comb)));
}

// Outlines whose ears come a few at a time: a comb's spine once its teeth are cut (a line of flat
// corners with an ear at each end), a zig-zag strip, a spiral band. Walking every corner round
// after round, and an ear's test sweeping the grid cells of its box, made these quadratic (100,000
// corners: 14-111 s in `accelviz info`); each is still cut whole, n - 2 triangles in its winding
// tiling it exactly once.
TEST(Polygon, OutlinesWhoseEarsComeFewAtATimeAreCutWhole) {
  std::vector<std::vector<glm::vec3>> shapes(3);
  for (int k = 0; k < 10000; ++k) {
    shapes[0].push_back({2.0f * k, 1.0f, 0.0f});
    shapes[0].push_back({2.0f * k + 1.0f, 0.2f, 0.0f});
  }
  shapes[0].push_back({shapes[0].back().x, -1.0f, 0.0f});
  shapes[0].push_back({0.0f, -1.0f, 0.0f});
  for (int i = 0; i < 10000; ++i) shapes[1].push_back({float(i), 1.0f + 0.5f * float(i % 2), 0.0f});
  for (int i = 9999; i >= 0; --i) shapes[1].push_back({float(i), -0.5f * float(i % 2), 0.0f});
  for (const double r0 : {1.0, 1.25})  // inner arm out, outer arm back: 32 turns, never touching
    for (int k = 0; k < 10000; ++k) {
      const int i = r0 == 1.0 ? k : 9999 - k;
      const double a = 0.02 * i, r = r0 + 0.0016 * i;
      shapes[2].push_back({float(r * std::cos(a)), float(r * std::sin(a)), 0.0f});
    }
  for (const std::vector<glm::vec3>& p : shapes) {
    const auto tris = triangulate_polygon(p);
    ASSERT_EQ(tris.size(), p.size() - 2);
    const double area = shoelace(p);
    double sum = 0.0;
    std::size_t wrong_way = 0;
    for (const auto& [i, j, k] : tris) {
      const glm::dvec3 a(p[i]), b(p[j]), c(p[k]);
      const double twice = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
      wrong_way += (area > 0.0 ? twice : -twice) < 0.0;
      sum += 0.5 * twice;
    }
    EXPECT_EQ(wrong_way, 0u) << p.size() << " corners";
    EXPECT_NEAR(sum, area, 1e-9 * std::abs(area)) << p.size() << " corners";
  }
}

// An ear whose corner lies far outside the reflex corners' rows: its row index was a float far
// beyond int's range, cast before it was clamped (undefined behaviour; the OBJ fuzzer found this
// pentagon, tests/fuzz/corpus/obj/ear_outside_reflex_rows.obj).
TEST(Polygon, AnEarFarOutsideTheReflexCornersRowsIsCut) {
  const std::vector<glm::vec3> p = {{0, 1, 0}, {2, 0, 0}, {2, 2, 0}, {0, 2, 0}, {-1, 1, 0}};
  const auto tris = triangulate_polygon(p);
  ASSERT_EQ(tris.size(), 3u);
  EXPECT_NEAR(covered(p, tris), shoelace(p), 1e-9);
}

// A convex face with flat corners (a T-junction's vertex on a straight side: a rectangle with a
// point on one side is the commonest pentagon of CAD exports) gives n - 2 triangles, none of zero
// area, tiling it exactly once in its winding, every outline edge used by one triangle as it is
// (no crack beside the neighbouring faces' triangles); the halving made (0, 1, 2) of three
// corners on one line. Over 8 flat corners on one triangle's sides the halving stays (a fan of
// slivers across the face would be worse): still n - 2 triangles tiling it once.
TEST(Polygon, FlatCornersOfAConvexFaceMakeNoZeroAreaTriangle) {
  // A rectangle (or a triangle) with `per_side[s]` corners spread along side s.
  const auto outline = [](std::vector<glm::vec3> strict, std::vector<int> per_side) {
    std::vector<glm::vec3> out;
    for (std::size_t s = 0; s < strict.size(); ++s) {
      const glm::vec3 a = strict[s], b = strict[(s + 1) % strict.size()];
      out.push_back(a);
      for (int k = 1; k <= per_side[s]; ++k) out.push_back(a + (b - a) * (float(k) / float(per_side[s] + 1)));
    }
    return out;
  };
  const std::vector<glm::vec3> rect = {{0, 0, 0}, {8, 0, 0}, {8, 4, 0}, {0, 4, 0}};
  const std::vector<glm::vec3> tri = {{0, 0, 0}, {8, 0, 0}, {0, 8, 0}};
  const std::vector<std::pair<std::vector<glm::vec3>, std::vector<int>>> cases = {
      {rect, {1, 0, 0, 0}}, {rect, {0, 0, 0, 1}},       {rect, {1, 1, 0, 0}}, {rect, {3, 0, 5, 0}},
      {rect, {2, 1, 3, 2}}, {rect, {100, 60, 100, 60}}, {tri, {1, 0, 0}},     {tri, {1, 1, 1}},
      {tri, {3, 2, 3}},     {tri, {0, 0, 4}},           {tri, {30, 0, 0}}};
  for (const auto& [strict, per_side] : cases) {
    for (int start = 0; start < 3; ++start) {  // the outline starting at a strict or a flat corner
      std::vector<glm::vec3> p = outline(strict, per_side);
      std::rotate(p.begin(), p.begin() + start, p.end());
      const std::size_t n = p.size();
      const auto tris = triangulate_polygon(p);
      ASSERT_EQ(tris.size(), n - 2) << n << " corners, start " << start;
      EXPECT_NEAR(covered(p, tris), shoelace(p), 1e-6 * shoelace(p));  // `covered` sums float cross products
      std::vector<int> used(n, 0);  // outline edge i -> i + 1, by the triangles' edges
      const bool fanned = n - strict.size() <= 8;
      for (const auto& t : tris) {
        const float area = glm::cross(p[t[1]] - p[t[0]], p[t[2]] - p[t[0]]).z;
        if (fanned)
          EXPECT_GT(area, 0.0f) << n << " corners, start " << start << ": (" << t[0] << ", " << t[1] << ", " << t[2]
                                << ")";
        else
          EXPECT_GE(area, 0.0f);
        for (int e = 0; e < 3; ++e)
          if ((t[e] + 1) % n == t[(e + 1) % 3]) ++used[t[e]];
      }
      EXPECT_EQ(std::count(used.begin(), used.end(), 1), static_cast<std::ptrdiff_t>(n)) << n << " corners";
    }
  }
  // A corner that turns back keeps the cut: n - 2 triangles all the same.
  const std::vector<glm::vec3> spike = {{0, 0, 0}, {4, 0, 0}, {2, 0, 0}, {2, 2, 0}, {0, 2, 0}};
  EXPECT_EQ(triangulate_polygon(spike).size(), 3u);
}

TEST(Polygon, DegenerateOutlinesStillGiveNMinusTwoTriangles) {
  const std::vector<glm::vec3> line = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}};  // no plane: fanned
  EXPECT_EQ(triangulate_polygon(line).size(), 2u);
  const std::vector<glm::vec3> bow = {{0, 0, 0}, {2, 2, 0}, {2, 0, 0}, {0, 2, 0}, {1, -1, 0}};
  EXPECT_EQ(triangulate_polygon(bow).size(), 3u);
  EXPECT_TRUE(triangulate_polygon(std::vector<glm::vec3>(2)).empty());
}

}  // namespace
}  // namespace accelviz::unity_test_polygon
