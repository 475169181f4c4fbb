// Polygon triangulation (core/geometry/polygon.h): convex faces keep their
// fan, concave ones are ear-clipped inside their outline within a bounded
// number of steps.
#include <gtest/gtest.h>

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

TEST(Polygon, AConvexFaceKeepsItsFan) {
  const std::vector<glm::vec3> hexagon = {{2, 0, 0}, {1, 2, 0}, {-1, 2, 0}, {-2, 0, 0}, {-1, -2, 0}, {1, -2, 0}};
  const auto tris = triangulate_polygon(hexagon);
  ASSERT_EQ(tris.size(), 4u);
  for (std::uint32_t k = 0; k < 4; ++k) EXPECT_EQ(tris[k], (std::array<std::uint32_t, 3>{0, k + 1, k + 2}));
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

TEST(Polygon, DegenerateOutlinesStillGiveNMinusTwoTriangles) {
  const std::vector<glm::vec3> line = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}};  // no plane: fanned
  EXPECT_EQ(triangulate_polygon(line).size(), 2u);
  const std::vector<glm::vec3> bow = {{0, 0, 0}, {2, 2, 0}, {2, 0, 0}, {0, 2, 0}, {1, -1, 0}};
  EXPECT_EQ(triangulate_polygon(bow).size(), 3u);
  EXPECT_TRUE(triangulate_polygon(std::vector<glm::vec3>(2)).empty());
}

}  // namespace
}  // namespace accelviz::unity_test_polygon
