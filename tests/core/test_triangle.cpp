// Named hard cases of the ray-triangle tests (core/geometry/triangle.h).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <utility>
#include <vector>

#include "core/geometry/triangle.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_triangle {

using namespace accelviz;

namespace {

bool watertight(const Ray& r, const Triangle& t, Hit* out = nullptr) {
  Hit h;
  const bool ok = intersect_watertight(r, WatertightRay(r.direction), t, r.tmin, r.tmax, h);
  if (out) *out = h;
  return ok;
}
bool fast(const Ray& r, const Triangle& t, Hit* out = nullptr) {
  Hit h;
  const bool ok = intersect_moller_trumbore(r, t, r.tmin, r.tmax, h);
  if (out) *out = h;
  return ok;
}

struct Lcg {
  std::uint64_t s;
  float next() {
    s = s * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<float>((s >> 40) * (1.0 / 16777216.0));
  }
  float range(float a, float b) { return a + (b - a) * next(); }
};

// A closed octahedron: 8 triangles, 12 shared edges, 6 shared vertices.
std::vector<Triangle> octahedron(const glm::vec3& c, float r) {
  const glm::vec3 px = c + glm::vec3(r, 0, 0), nx = c - glm::vec3(r, 0, 0);
  const glm::vec3 py = c + glm::vec3(0, r, 0), ny = c - glm::vec3(0, r, 0);
  const glm::vec3 pz = c + glm::vec3(0, 0, r), nz = c - glm::vec3(0, 0, r);
  return {{px, py, pz}, {py, nx, pz}, {nx, ny, pz}, {ny, px, pz},
          {py, px, nz}, {nx, py, nz}, {ny, nx, nz}, {px, ny, nz}};
}

int count_hits(const std::vector<Triangle>& tris, const Ray& r, bool use_watertight) {
  int n = 0;
  for (const Triangle& t : tris) n += use_watertight ? watertight(r, t) : fast(r, t);
  return n;
}

}  // namespace

TEST(Triangle, CentreHitBarycentricsAndT) {
  const Triangle t{{0, 0, 2}, {1, 0, 2}, {0, 1, 2}};
  for (bool wt : {true, false}) {
    Hit h;
    const Ray r({0.25f, 0.25f, 0}, {0, 0, 1});
    ASSERT_TRUE(wt ? watertight(r, t, &h) : fast(r, t, &h));
    EXPECT_NEAR(h.t, 2.0f, 1e-6f);
    EXPECT_NEAR(h.u, 0.25f, 1e-6f);
    EXPECT_NEAR(h.v, 0.25f, 1e-6f);
  }
  EXPECT_EQ(triangle_normal(t), glm::vec3(0, 0, 1));
}

TEST(Triangle, BothWindingsHit) {
  const Triangle a{{0, 0, 2}, {1, 0, 2}, {0, 1, 2}};
  const Triangle b{{0, 0, 2}, {0, 1, 2}, {1, 0, 2}};
  const Ray r({0.2f, 0.2f, 0}, {0, 0, 1});
  EXPECT_TRUE(watertight(r, a));
  EXPECT_TRUE(watertight(r, b));
  EXPECT_TRUE(fast(r, a));
  EXPECT_TRUE(fast(r, b));
}

TEST(Triangle, IntervalIsClosed) {
  const Triangle t{{0, 0, 2}, {1, 0, 2}, {0, 1, 2}};
  EXPECT_TRUE(watertight(Ray({0.2f, 0.2f, 0}, {0, 0, 1}, 0.0f, 2.0f), t));
  EXPECT_FALSE(watertight(Ray({0.2f, 0.2f, 0}, {0, 0, 1}, 0.0f, 1.999f), t));
  EXPECT_FALSE(watertight(Ray({0.2f, 0.2f, 0}, {0, 0, 1}, 2.001f, kInfinity), t));
  EXPECT_FALSE(watertight(Ray({0.2f, 0.2f, 3}, {0, 0, 1}), t));  // behind the origin
}

TEST(TriangleHardCases, RayThroughSharedEdgeOfClosedMeshNeverMisses) {
  // Rays from inside a closed octahedron aimed exactly at points on its edges
  // (float-rounded) must hit at least one triangle with the watertight test.
  const glm::vec3 c(0.3f, -0.7f, 0.11f);
  const auto tris = octahedron(c, 1.7f);
  Lcg rng{7};
  int fast_misses = 0;
  for (int i = 0; i < 20000; ++i) {
    const Triangle& t = tris[i % 8];
    const float s = rng.next();
    const glm::vec3 target = t.v0 + s * (t.v1 - t.v0);
    const glm::vec3 o = c + glm::vec3{rng.range(-0.3f, 0.3f), rng.range(-0.3f, 0.3f), rng.range(-0.3f, 0.3f)};
    const Ray r(o, target - o);
    ASSERT_GE(count_hits(tris, r, true), 1) << "watertight miss through an edge, i=" << i;
    fast_misses += count_hits(tris, r, false) == 0;
  }
  // Moller-Trumbore is allowed to leak; we only record it (the sweep shows it).
  RecordProperty("moller_trumbore_edge_misses", fast_misses);
}

TEST(TriangleHardCases, RayThroughSharedVertexOfClosedMeshNeverMisses) {
  const glm::vec3 c(-0.25f, 0.5f, 1.0f);
  const auto tris = octahedron(c, 1.0f);
  Lcg rng{11};
  for (int i = 0; i < 6000; ++i) {
    const Triangle& t = tris[i % 8];
    const glm::vec3 target = (i % 3 == 0) ? t.v0 : (i % 3 == 1 ? t.v1 : t.v2);
    const glm::vec3 o = c + glm::vec3{rng.range(-0.2f, 0.2f), rng.range(-0.2f, 0.2f), rng.range(-0.2f, 0.2f)};
    ASSERT_GE(count_hits(tris, Ray(o, target - o), true), 1) << "i=" << i;
  }
}

TEST(TriangleHardCases, RayFromOutsideThroughSharedEdgeOfQuad) {
  // Two triangles sharing the diagonal of a unit quad; rays along z through the
  // diagonal (x == y exactly) hit one or both, never neither.
  const Triangle a{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}};
  const Triangle b{{0, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  for (int i = 1; i < 1000; ++i) {
    const float s = i / 1000.0f;
    for (const glm::vec3 d : {glm::vec3(0, 0, -1), glm::vec3(0.1f, 0.2f, -1), glm::vec3(-0.3f, 0.05f, -1)}) {
      const glm::vec3 o = glm::vec3(s, s, 0) - 2.0f * d;  // passes through (s, s, 0)
      const Ray r(o, d);
      ASSERT_GE(int(watertight(r, a)) + int(watertight(r, b)), 1) << "s=" << s;
    }
  }
}

TEST(TriangleHardCases, AxisAlignedRaysWithSignedZeroDirections) {
  const Triangle t{{-1, -1, 5}, {1, -1, 5}, {0, 1, 5}};
  for (float zx : {+0.0f, -0.0f})
    for (float zy : {+0.0f, -0.0f}) {
      EXPECT_TRUE(watertight(Ray({0, 0, 0}, {zx, zy, 1}), t));
      EXPECT_TRUE(fast(Ray({0, 0, 0}, {zx, zy, 1}), t));
    }
  // Dominant axis negative (kx/ky swapped to keep the winding).
  EXPECT_TRUE(watertight(Ray({0, 0, 10}, {-0.0f, 0.0f, -1}), t));
}

TEST(TriangleHardCases, GrazingRayInTrianglePlaneReportsNoHit) {
  // A ray lying in the triangle's plane has det == 0: no (ill-defined) hit.
  const Triangle t{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  EXPECT_FALSE(watertight(Ray({-1, 0.2f, 0}, {1, 0, 0}), t));
  EXPECT_FALSE(fast(Ray({-1, 0.2f, 0}, {1, 0, 0}), t));
}

TEST(TriangleHardCases, DegenerateTrianglesNeverHit) {
  const Triangle zero_area{{0, 0, 1}, {1, 1, 1}, {2, 2, 1}};  // collinear
  const Triangle repeated{{0, 0, 1}, {0, 0, 1}, {1, 0, 1}};   // repeated vertex
  const Triangle point{{0.5f, 0.5f, 1}, {0.5f, 0.5f, 1}, {0.5f, 0.5f, 1}};
  for (const Triangle& t : {zero_area, repeated, point}) {
    EXPECT_FALSE(watertight(Ray({0.5f, 0.5f, 0}, {0, 0, 1}), t));
    EXPECT_FALSE(watertight(Ray({1, 1, 0}, {0, 0, 1}), t));
    EXPECT_FALSE(fast(Ray({0.5f, 0.5f, 0}, {0, 0, 1}), t));
    EXPECT_EQ(triangle_normal(t), glm::vec3(0.0f));
  }
}

TEST(TriangleHardCases, TinyCoordinates1e20) {
  // A triangle at 1e-20 scale, viewed from 1e-20 away and from 1 away.
  const float s = 1e-20f;
  const Triangle t{{0, 0, 2 * s}, {s, 0, 2 * s}, {0, s, 2 * s}};
  Hit h;
  ASSERT_TRUE(watertight(Ray({0.25f * s, 0.25f * s, 0}, {0, 0, 1}), t, &h));
  EXPECT_NEAR(h.t / (2 * s), 1.0f, 1e-5f);
  EXPECT_NEAR(h.u, 0.25f, 1e-4f);
  ASSERT_TRUE(watertight(Ray({0.25f * s, 0.25f * s, -1}, {0, 0, 1}), t, &h));
  EXPECT_NEAR(h.t, 1.0f, 1e-5f);
  EXPECT_FALSE(watertight(Ray({1.5f * s, 0.25f * s, 0}, {0, 0, 1}), t));
}

TEST(TriangleHardCases, HugeCoordinates1e20) {
  const float s = 1e20f;
  const Triangle t{{-s, -s, 3 * s}, {s, -s, 3 * s}, {0, s, 3 * s}};
  Hit h;
  ASSERT_TRUE(watertight(Ray({0, 0, 0}, {0, 0, 1}), t, &h));
  EXPECT_NEAR(h.t / (3 * s), 1.0f, 1e-5f);
  ASSERT_TRUE(watertight(Ray({0.1f * s, 0.2f * s, 0}, {0, 0, 1}), t, &h));
  EXPECT_FALSE(watertight(Ray({2 * s, 0, 0}, {0, 0, 1}), t));
  // Normal computed without overflow.
  EXPECT_NEAR(glm::length(triangle_normal(t)), 1.0f, 1e-6f);
}

TEST(TriangleHardCases, SceneTranslatedBy1e7) {
  // At 1e7 the float spacing is 1: a closed octahedron of radius 64 there,
  // rays from inside toward its edges still never leak.
  const glm::vec3 c(1e7f, -1e7f, 1e7f);
  const auto tris = octahedron(c, 64.0f);
  Lcg rng{3};
  for (int i = 0; i < 5000; ++i) {
    const Triangle& t = tris[i % 8];
    const glm::vec3 target = t.v0 + std::floor(rng.next() * 64.0f) / 64.0f * (t.v1 - t.v0);
    const glm::vec3 o = c + glm::vec3{std::floor(rng.range(-8, 8)), std::floor(rng.range(-8, 8)), 1.0f};
    ASSERT_GE(count_hits(tris, Ray(o, target - o), true), 1) << "i=" << i;
  }
}
// WatertightRay's constructor picks the axes without branches (triangle.h);
// it must pick exactly what the paper's nested selection picks, including
// on ties between components (the first axis of equal maxima wins x over y,
// z otherwise), on signed zeros and on negative dominant components (x and y
// swapped to keep the winding), and divide the same operands.
TEST(TriangleHardCases, WatertightAxesMatchTheNestedSelectionOnTiesAndSignedZeros) {
  const auto nested = [](const glm::vec3& dir) {
    WatertightRay w;
    const glm::vec3 a = glm::abs(dir);
    w.kz = (a.x > a.y) ? (a.x > a.z ? 0 : 2) : (a.y > a.z ? 1 : 2);
    w.kx = (w.kz + 1) % 3;
    w.ky = (w.kx + 1) % 3;
    if (dir[w.kz] < 0.0f) std::swap(w.kx, w.ky);
    w.sx = dir[w.kx] / dir[w.kz];
    w.sy = dir[w.ky] / dir[w.kz];
    w.sz = 1.0f / dir[w.kz];
    return w;
  };
  const float values[] = {0.0f, -0.0f, 1.0f, -1.0f, 0.5f, -0.5f, 2.0f, -2.0f, 1e-30f, -1e30f};
  int checked = 0, swapped = 0, ties = 0;
  const auto check = [&](const glm::vec3& d) {
    if (d.x == 0.0f && d.y == 0.0f && d.z == 0.0f) return;  // not a direction
    const WatertightRay got(d), want = nested(d);
    ASSERT_EQ(got.kx, want.kx) << d.x << " " << d.y << " " << d.z;
    ASSERT_EQ(got.ky, want.ky) << d.x << " " << d.y << " " << d.z;
    ASSERT_EQ(got.kz, want.kz) << d.x << " " << d.y << " " << d.z;
    // Bit for bit (NaN-free here: the dominant component is never zero).
    ASSERT_EQ(std::memcmp(&got.sx, &want.sx, sizeof(float)), 0) << d.x << " " << d.y << " " << d.z;
    ASSERT_EQ(std::memcmp(&got.sy, &want.sy, sizeof(float)), 0) << d.x << " " << d.y << " " << d.z;
    ASSERT_EQ(std::memcmp(&got.sz, &want.sz, sizeof(float)), 0) << d.x << " " << d.y << " " << d.z;
    ++checked;
    swapped += d[want.kz] < 0.0f;
    ties += std::fabs(d.x) == std::fabs(d.y) || std::fabs(d.y) == std::fabs(d.z) || std::fabs(d.x) == std::fabs(d.z);
  };
  for (float x : values)
    for (float y : values)
      for (float z : values) check({x, y, z});
  Lcg rng{7};
  for (int i = 0; i < 100000; ++i) check({rng.range(-1, 1), rng.range(-1, 1), rng.range(-1, 1)});
  EXPECT_GT(swapped, 1000);  // both signs of the dominant axis were exercised
  EXPECT_GT(ties, 400);      // and ties between components (from the table)
  EXPECT_GT(checked, 100900);
}
}  // namespace unity_test_triangle
