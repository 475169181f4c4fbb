// Plane, sphere, capped cylinder and the secondary-ray offset (core/geometry/shapes.h).
#include <gtest/gtest.h>

#include <cmath>

#include "core/geometry/shapes.h"
#include "core/geometry/triangle.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_shapes {

using namespace accelviz;

TEST(Plane, HitAndParallelMiss) {
  Hit h;
  ASSERT_TRUE(intersect_plane(Ray({0, 5, 0}, {0, -1, 0}), Plane{{0, 1, 0}, {0, 2, 0}}, 0, kInfinity, h));
  EXPECT_FLOAT_EQ(h.t, 4.0f);
  EXPECT_EQ(h.ng, glm::vec3(0, 1, 0));
  EXPECT_FALSE(intersect_plane(Ray({0, 5, 0}, {1, 0, 0}), Plane{{0, 1, 0}, {0, 1, 0}}, 0, kInfinity, h));
  // Off-centre plane, tilted.
  ASSERT_TRUE(intersect_plane(Ray({3, 0, 0}, {0, 0, 1}), Plane{{3, 0, 7}, {0.3f, 0.1f, 1}}, 0, kInfinity, h));
  EXPECT_NEAR(h.t, 7.0f, 1e-5f);
}

TEST(Sphere, CentredAndOffCentre) {
  Hit h;
  ASSERT_TRUE(intersect_sphere(Ray({0, 0, -5}, {0, 0, 1}), Sphere{{0, 0, 0}, 1}, 0, kInfinity, h));
  EXPECT_NEAR(h.t, 4.0f, 1e-6f);
  EXPECT_NEAR(h.ng.z, -1.0f, 1e-6f);
  ASSERT_TRUE(intersect_sphere(Ray({10, 20, -5}, {0, 0, 2}), Sphere{{10, 20.5f, 3}, 1}, 0, kInfinity, h));
  EXPECT_NEAR(h.t * 2.0f, 8.0f - std::sqrt(0.75f), 1e-5f);
  EXPECT_FALSE(intersect_sphere(Ray({10, 22, -5}, {0, 0, 1}), Sphere{{10, 20.5f, 3}, 1}, 0, kInfinity, h));
  // From inside: the far root.
  ASSERT_TRUE(intersect_sphere(Ray({0, 0, 0}, {1, 0, 0}), Sphere{{0, 0, 0}, 2}, 0, kInfinity, h));
  EXPECT_NEAR(h.t, 2.0f, 1e-6f);
}

TEST(Sphere, FarAwaySphereKeepsPrecision) {
  Hit h;
  ASSERT_TRUE(intersect_sphere(Ray({0, 0, 0}, {0, 0, 1}), Sphere{{0, 0, 1e6f}, 1}, 0, kInfinity, h));
  EXPECT_NEAR(h.t, 1e6f - 1.0f, 0.1f);
}

TEST(Cylinder, CentredLateralAndCaps) {
  const Cylinder c{{0, 0, 0}, {0, 1, 0}, 1.0f, 2.0f};
  Hit h;
  ASSERT_TRUE(intersect_cylinder(Ray({-5, 1, 0}, {1, 0, 0}), c, 0, kInfinity, h));
  EXPECT_NEAR(h.t, 4.0f, 1e-5f);
  EXPECT_NEAR(h.ng.x, -1.0f, 1e-5f);
  ASSERT_TRUE(intersect_cylinder(Ray({0.3f, 10, 0.2f}, {0, -1, 0}), c, 0, kInfinity, h));  // top cap
  EXPECT_NEAR(h.t, 8.0f, 1e-5f);
  EXPECT_NEAR(h.ng.y, 1.0f, 1e-6f);
  ASSERT_TRUE(intersect_cylinder(Ray({0.3f, -3, 0.2f}, {0, 1, 0}), c, 0, kInfinity, h));  // bottom cap
  EXPECT_NEAR(h.t, 3.0f, 1e-5f);
  EXPECT_NEAR(h.ng.y, -1.0f, 1e-6f);
  EXPECT_FALSE(intersect_cylinder(Ray({-5, 2.5f, 0}, {1, 0, 0}), c, 0, kInfinity, h));   // above the top
  EXPECT_FALSE(intersect_cylinder(Ray({1.5f, 10, 0}, {0, -1, 0}), c, 0, kInfinity, h));  // outside the radius
}

TEST(Cylinder, OffCentreTiltedAxis) {
  const glm::vec3 axis = glm::normalize(glm::vec3(1, 1, 0));
  const Cylinder c{{5, -2, 3}, axis, 0.5f, 4.0f};
  // A ray perpendicular to the axis through the point 2 along the axis.
  const glm::vec3 p = glm::vec3(5, -2, 3) + 2.0f * axis;
  const glm::vec3 perp(0, 0, 1);
  Hit h;
  ASSERT_TRUE(intersect_cylinder(Ray(p - 10.0f * perp, perp), c, 0, kInfinity, h));
  EXPECT_NEAR(h.t, 9.5f, 1e-4f);
  EXPECT_NEAR(h.ng.z, -1.0f, 1e-4f);
  // Along the axis from below the base: hits the base cap at distance 3.
  ASSERT_TRUE(intersect_cylinder(Ray(glm::vec3(5, -2, 3) - 3.0f * axis, axis), c, 0, kInfinity, h));
  EXPECT_NEAR(h.t, 3.0f, 1e-4f);
}

TEST(OffsetHardCases, ShadowRayDoesNotReHitItsOwnTriangleAtManyScales) {
  // For a triangle at scales 1e-3 .. 1e7 from the origin, a ray from an
  // offset hit point toward the light must not hit the same triangle again.
  std::uint64_t s = 99;
  auto rnd = [&] {
    s = s * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<float>((s >> 40) * (1.0 / 16777216.0));
  };
  for (float scale : {1e-3f, 1.0f, 1e3f, 1e5f, 1e7f}) {
    const glm::vec3 base(scale, -0.5f * scale, 0.25f * scale);
    const Triangle t{base, base + glm::vec3(scale, 0.1f * scale, 0),
                     base + glm::vec3(0.2f * scale, scale, 0.3f * scale)};
    const glm::vec3 n = triangle_normal(t);
    int self_hits = 0;
    for (int i = 0; i < 2000; ++i) {
      float u = rnd(), v = rnd();
      if (u + v > 1) u = 1 - u, v = 1 - v;
      const glm::vec3 p = t.v0 + u * (t.v1 - t.v0) + v * (t.v2 - t.v0);
      const glm::vec3 dir = glm::normalize(n + 0.9f * glm::vec3(rnd() - 0.5f, rnd() - 0.5f, rnd() - 0.5f));
      const glm::vec3 nn = glm::dot(n, dir) >= 0 ? n : -n;
      const glm::vec3 o = offset_ray_origin(p, nn);
      Hit h;
      const Ray r(o, dir);
      self_hits += intersect_watertight(r, WatertightRay(dir), t, 0.0f, kInfinity, h);
    }
    EXPECT_EQ(self_hits, 0) << "scale " << scale;
  }
}

TEST(OffsetHardCases, OffsetIsSmallRelativeToScale) {
  // Away from the origin: a fixed number of ULPs, i.e. relative to the coordinate.
  for (float scale : {1.0f, 1e3f, 1e7f}) {
    const glm::vec3 p(scale, scale, scale);
    const glm::vec3 o = offset_ray_origin(p, glm::vec3(0, 0, 1));
    EXPECT_GT(o.z, p.z);
    EXPECT_LT((o.z - p.z) / scale, 1e-4f);
    EXPECT_EQ(o.x, p.x);
  }
  // Near the origin (|p| < 1/32): a fixed absolute offset of 1/65536.
  const glm::vec3 p(1e-3f, 1e-3f, 1e-3f);
  const glm::vec3 o = offset_ray_origin(p, glm::vec3(0, 0, -1));
  EXPECT_FLOAT_EQ(p.z - o.z, 1.0f / 65536.0f);
}
}  // namespace unity_test_shapes
