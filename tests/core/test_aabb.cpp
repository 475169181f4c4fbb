// Named hard cases of the ray-box slab test (core/math/aabb.h).
#include <gtest/gtest.h>

#include <cmath>

#include "core/math/aabb.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_aabb {

using namespace accelviz;

namespace {
const Aabb kUnit{{0, 0, 0}, {1, 1, 1}};

bool hits(const Aabb& b, const Ray& r, SlabInterval* iv = nullptr) {
  SlabInterval tmp;
  const bool h = intersect_slab(b, r, tmp);
  if (iv) *iv = tmp;
  EXPECT_FALSE(std::isnan(tmp.t_entry)) << "entry must never be NaN";
  EXPECT_FALSE(std::isnan(tmp.t_exit)) << "exit must never be NaN";
  return h;
}
}  // namespace

TEST(Aabb, SurfaceAreaAndEmpty) {
  EXPECT_FLOAT_EQ(kUnit.surface_area(), 6.0f);
  EXPECT_FLOAT_EQ(kUnit.half_area(), 3.0f);
  EXPECT_TRUE(Aabb::empty().is_empty());
  EXPECT_EQ(Aabb::empty().surface_area(), 0.0f);
  Aabb b;
  b.extend(glm::vec3(1, 2, 3));
  EXPECT_FALSE(b.is_empty());
  EXPECT_EQ(b.surface_area(), 0.0f);  // a point box has zero area
  EXPECT_TRUE(kUnit.contains(glm::vec3(1, 0.5f, 0)));
  EXPECT_FALSE(kUnit.contains(glm::vec3(1.01f, 0.5f, 0)));
}

TEST(SlabHardCases, EntryExitDistances) {
  SlabInterval iv;
  ASSERT_TRUE(hits(kUnit, Ray({-1, 0.5f, 0.5f}, {1, 0, 0}), &iv));
  EXPECT_FLOAT_EQ(iv.t_entry, 1.0f);
  EXPECT_NEAR(iv.t_exit, 2.0f, 1e-5f);
  EXPECT_GE(iv.t_exit, 2.0f) << "exit is padded outward, never inward";
}

TEST(SlabHardCases, PositiveZeroDirectionInsideSlab) {
  EXPECT_TRUE(hits(kUnit, Ray({-1, 0.5f, 0.5f}, {1, +0.0f, +0.0f})));
}

TEST(SlabHardCases, NegativeZeroDirectionInsideSlab) {
  EXPECT_TRUE(hits(kUnit, Ray({-1, 0.5f, 0.5f}, {1, -0.0f, -0.0f})));
  EXPECT_TRUE(hits(kUnit, Ray({2, 0.5f, 0.5f}, {-1, -0.0f, +0.0f})));
}

TEST(SlabHardCases, ZeroDirectionOutsideSlabMisses) {
  EXPECT_FALSE(hits(kUnit, Ray({-1, 1.5f, 0.5f}, {1, 0.0f, 0.0f})));
  EXPECT_FALSE(hits(kUnit, Ray({-1, 1.5f, 0.5f}, {1, -0.0f, 0.0f})));
  EXPECT_FALSE(hits(kUnit, Ray({-1, -0.5f, 0.5f}, {1, -0.0f, 0.0f})));
}

TEST(SlabHardCases, RayLyingInLowerFacePlaneWithPlusAndMinusZero) {
  // Origin exactly on the y = 0 plane, direction y component +0 / -0: 0*inf = NaN
  // must not poison the interval; a ray in a face plane touches the box.
  EXPECT_TRUE(hits(kUnit, Ray({-1, 0.0f, 0.5f}, {1, +0.0f, 0})));
  EXPECT_TRUE(hits(kUnit, Ray({-1, 0.0f, 0.5f}, {1, -0.0f, 0})));
}

TEST(SlabHardCases, RayLyingInUpperFacePlaneWithPlusAndMinusZero) {
  EXPECT_TRUE(hits(kUnit, Ray({-1, 1.0f, 0.5f}, {1, +0.0f, 0})));
  EXPECT_TRUE(hits(kUnit, Ray({-1, 1.0f, 0.5f}, {1, -0.0f, 0})));
}

TEST(SlabHardCases, RayAlongBoxEdge) {
  // In two face planes at once (the edge y = 0, z = 1).
  EXPECT_TRUE(hits(kUnit, Ray({-1, 0.0f, 1.0f}, {1, -0.0f, +0.0f})));
}

TEST(SlabHardCases, OriginOnBoxFace) {
  SlabInterval iv;
  ASSERT_TRUE(hits(kUnit, Ray({0.0f, 0.5f, 0.5f}, {1, 0.3f, 0.2f}), &iv));
  EXPECT_EQ(iv.t_entry, 0.0f);
  // Leaving through the face it starts on: touches at t = 0 only.
  ASSERT_TRUE(hits(kUnit, Ray({0.0f, 0.5f, 0.5f}, {-1, 0.3f, 0.2f}), &iv));
  EXPECT_EQ(iv.t_entry, 0.0f);
  EXPECT_GE(iv.t_exit, 0.0f);
}

TEST(SlabHardCases, OriginInsideBox) {
  SlabInterval iv;
  ASSERT_TRUE(hits(kUnit, Ray({0.5f, 0.5f, 0.5f}, {0, 0, -1}), &iv));
  EXPECT_EQ(iv.t_entry, 0.0f);
  EXPECT_NEAR(iv.t_exit, 0.5f, 1e-6f);
}

TEST(SlabHardCases, SegmentEndsBeforeBox) {
  EXPECT_FALSE(hits(kUnit, Ray({-1, 0.5f, 0.5f}, {1, 0, 0}, 0.0f, 0.99f)));
  EXPECT_TRUE(hits(kUnit, Ray({-1, 0.5f, 0.5f}, {1, 0, 0}, 0.0f, 1.0f)));  // tmax exactly at the face
  EXPECT_FALSE(hits(kUnit, Ray({-1, 0.5f, 0.5f}, {1, 0, 0}, 2.1f, kInfinity)));
}

TEST(SlabHardCases, InfiniteTmaxAndBoxBehind) {
  EXPECT_TRUE(hits(kUnit, Ray({-1e30f, 0.5f, 0.5f}, {1, 0, 0}, 0.0f, kInfinity)));
  EXPECT_FALSE(hits(kUnit, Ray({2, 0.5f, 0.5f}, {1, 0, 0})));
}

TEST(SlabHardCases, FlatBoxZeroExtent) {
  // A box of zero thickness (a flat axis-aligned wall's bounds) is hit by a
  // ray crossing it and by a ray lying in it.
  const Aabb flat{{0, 0, 0}, {1, 1, 0}};
  EXPECT_TRUE(hits(flat, Ray({0.5f, 0.5f, -1}, {0, 0, 1})));
  EXPECT_TRUE(hits(flat, Ray({-1, 0.5f, 0.0f}, {1, 0, -0.0f})));
  EXPECT_FALSE(hits(flat, Ray({-1, 0.5f, 0.001f}, {1, 0, 0.0f})));
}

TEST(SlabHardCases, PaddingNeverShrinksTheInterval) {
  // Random rays: the padded test accepts every box the plain test accepts,
  // and its exit distance is never smaller.
  std::uint32_t s = 12345;
  auto rnd = [&] {
    s = s * 1664525u + 1013904223u;
    return (s >> 8) * (1.0f / 16777216.0f);
  };
  for (int i = 0; i < 20000; ++i) {
    const glm::vec3 o(rnd() * 4 - 2, rnd() * 4 - 2, rnd() * 4 - 2);
    const glm::vec3 d(rnd() * 2 - 1, rnd() * 2 - 1, rnd() * 2 - 1);
    const Ray r(o, d);
    SlabInterval a, b;
    const bool plain = intersect_slab_plain(kUnit, r, a);
    const bool padded = intersect_slab(kUnit, r, b);
    if (plain) {
      ASSERT_TRUE(padded);
      ASSERT_GE(b.t_exit, a.t_exit);
    }
  }
}
}  // namespace unity_test_aabb
