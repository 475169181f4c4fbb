// The BVH's inline ray/triangle tests (core/accel/bvh/bvh_triangle.h) against
// the out-of-line ones of core/geometry/triangle.cpp: the same hit/miss and
// bit for bit the same t, u, v, on random input and on the cases that take
// the special paths (rays through shared edges and vertices, axis-aligned
// rays, huge and tiny coordinates, degenerate triangles, t at the interval
// ends). The wide path's four-lane tests (Moller-Trumbore, and watertight
// with its special lanes sent to the scalar test) are checked against the
// scalar ones on the same inputs, and the 8-wide walk's two-block tests
// (bvh_tri8.h) lane by lane against the four-lane ones.
#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <vector>

#include "core/accel/bvh/bvh_tri4.h"
#include "core/accel/bvh/bvh_tri8.h"
#include "core/accel/bvh/bvh_triangle.h"
#include "core/accel/bvh/bvh_wide.h"
#include "tests/core/mt_random.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_bvh_triangle {

using namespace accelviz;

namespace {

using test_random::uniform;

bool same_bits(float a, float b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}

struct Counts {
  int hits = 0, misses = 0;
};

void expect_same(const Ray& ray, const Triangle& tri, float tmin, float tmax, Counts& c) {
  const WatertightRay wr(ray.direction);
  const bvh_detail::InlineWatertightRay iwr(ray);
  Hit a, b;
  const bool ha = intersect_watertight(ray, wr, tri, tmin, tmax, a);
  const bool hb = bvh_detail::intersect_watertight_inline(ray, iwr, tri, tmin, tmax, b);
  ASSERT_EQ(ha, hb);
  if (ha) {
    ++c.hits;
    ASSERT_TRUE(same_bits(a.t, b.t) && same_bits(a.u, b.u) && same_bits(a.v, b.v))
        << a.t << " " << b.t << " " << a.u << " " << b.u;
  } else {
    ++c.misses;
  }
  Hit m, n;
  const bool hm = intersect_moller_trumbore(ray, tri, tmin, tmax, m);
  const bool hn = bvh_detail::intersect_moller_trumbore_inline(ray, tri, tmin, tmax, n);
  ASSERT_EQ(hm, hn);
  if (hm) {
    ASSERT_TRUE(same_bits(m.t, n.t) && same_bits(m.u, n.u) && same_bits(m.v, n.v));
  }
#ifdef ACCELVIZ_BVH_TRI4_SSE2
  // The wide path's four-lane Moller-Trumbore (bvh_tri4.h), the triangle in
  // every lane (a block of one: padding lanes repeat it): each lane must be
  // the scalar test bit for bit.
  std::vector<bvh_detail::TriBlock4> blocks;
  bvh_detail::append_tri4_blocks([&](std::uint32_t) -> const Triangle& { return tri; }, 0, 1, blocks);
  bvh_detail::Tri4MtResult r4;
  bvh_detail::intersect_tri4_mt(blocks[0], bvh_detail::Tri4MtRay(ray), tmin, r4);
  for (int l = 0; l < 4; ++l) {
    const bool h4 = ((r4.candidate >> l) & 1) && r4.t[l] <= tmax;
    ASSERT_EQ(h4, hm) << "lane " << l;
    if (hm) {
      ASSERT_TRUE(same_bits(m.t, r4.t[l]) && same_bits(m.u, r4.u[l]) && same_bits(m.v, r4.v[l])) << "lane " << l;
    }
  }
  // The four-lane watertight test as the wide walk uses it: a special lane
  // goes to the scalar test, a candidate lane is accepted against tmax.
  bvh_detail::Tri4Result w4;
  bvh_detail::intersect_tri4(blocks[0], bvh_detail::Tri4Ray(iwr), tmin, w4);
  for (int l = 0; l < 4; ++l) {
    Hit h;
    bool h4 = false;
    if ((w4.special >> l) & 1) {
      h4 = bvh_detail::intersect_watertight_inline(ray, iwr, tri, tmin, tmax, h);
    } else if ((w4.candidate >> l) & 1) {
      h4 = bvh_detail::tri4_accept(w4, l, tmax);
      h.t = w4.t[l];
      h.u = w4.u[l];
      h.v = w4.v[l];
    }
    ASSERT_EQ(h4, ha) << "watertight lane " << l;
    if (ha) {
      ASSERT_TRUE(same_bits(a.t, h.t) && same_bits(a.u, h.u) && same_bits(a.v, h.v)) << "watertight lane " << l;
    }
  }
#endif
}

#ifdef ACCELVIZ_BVH_WIDE8_AVX2
/// Both two-block tests on blocks b[0], b[1] (AVX2 code: called only when
/// the CPU has it).
[[gnu::target("avx2")]] void run_tri8(const bvh_detail::TriBlock4* b, const Ray& ray, float tmin,
                                      bvh_detail::Tri8Result& w, bvh_detail::Tri8MtResult& m) {
  bvh_detail::intersect_tri8(b, bvh_detail::InlineWatertightRay(ray), tmin, w);
  bvh_detail::intersect_tri8_mt(b, ray, tmin, m);
}
#endif

/// The two-block tests on a block of `first` (lanes 0-3) and one of
/// `second` (lanes 4-7) against the four-lane tests on each block: the same
/// candidate and special lanes, and bit for bit the same figures in every
/// candidate lane. Returns the number of lanes compared (0 without AVX2).
int expect_pair_same(const Ray& ray, const Triangle& first, const Triangle& second, float tmin) {
#ifdef ACCELVIZ_BVH_WIDE8_AVX2
  if (!bvh_detail::cpu_has_wide8()) return 0;
  std::vector<bvh_detail::TriBlock4> blocks;
  bvh_detail::append_tri4_blocks([&](std::uint32_t) -> const Triangle& { return first; }, 0, 1, blocks);
  bvh_detail::append_tri4_blocks([&](std::uint32_t) -> const Triangle& { return second; }, 0, 2, blocks);
  blocks[1].v[0][1] += 0.25f * (blocks[1].v[3][1] - blocks[1].v[0][1]);  // lane 5: another triangle
  bvh_detail::Tri8Result w8;
  bvh_detail::Tri8MtResult m8;
  run_tri8(blocks.data(), ray, tmin, w8, m8);
  EXPECT_EQ(bvh_detail::tri8_used_lanes(blocks.data()), 0x31);
  const bvh_detail::InlineWatertightRay iwr(ray);
  for (int half = 0; half < 2; ++half) {
    bvh_detail::Tri4Result w4;
    bvh_detail::intersect_tri4(blocks[half], bvh_detail::Tri4Ray(iwr), tmin, w4);
    bvh_detail::Tri4MtResult m4;
    bvh_detail::intersect_tri4_mt(blocks[half], bvh_detail::Tri4MtRay(ray), tmin, m4);
    EXPECT_EQ((w8.candidate >> (4 * half)) & 0xF, w4.candidate) << "half " << half;
    EXPECT_EQ((w8.special >> (4 * half)) & 0xF, w4.special) << "half " << half;
    EXPECT_EQ((m8.candidate >> (4 * half)) & 0xF, m4.candidate) << "half " << half;
    for (int l = 0; l < 4; ++l) {
      const int k = 4 * half + l;
      if ((w4.candidate >> l) & 1) {
        EXPECT_TRUE(same_bits(w8.T[k], w4.T[l]) && same_bits(w8.det[k], w4.det[l]) && same_bits(w8.t[k], w4.t[l]) &&
                    same_bits(w8.u[k], w4.u[l]) && same_bits(w8.v[k], w4.v[l]))
            << "watertight lane " << k;
      }
      EXPECT_TRUE(same_bits(m8.t[k], m4.t[l]) && same_bits(m8.u[k], m4.u[l]) && same_bits(m8.v[k], m4.v[l]))
          << "Moller-Trumbore lane " << k;
    }
  }
  return 8;
#else
  (void)ray, (void)first, (void)second, (void)tmin;
  return 0;
#endif
}

glm::vec3 rand_vec(std::mt19937& rng, float scale) {
  return scale * glm::vec3{2 * uniform(rng) - 1, 2 * uniform(rng) - 1, 2 * uniform(rng) - 1};
}

}  // namespace

TEST(BvhInlineTriangle, RandomRaysAndTrianglesAgreeBitForBit) {
  std::mt19937 rng(7);
  Counts c;
  long pair_lanes = 0;
  for (int i = 0; i < 200000; ++i) {
    const Triangle tri{rand_vec(rng, 1), rand_vec(rng, 1), rand_vec(rng, 1)};
    // Aim at a random point of the triangle's plane region half the time.
    const glm::vec3 o = rand_vec(rng, 3);
    const float u = uniform(rng) * 1.4f - 0.2f, v = uniform(rng) * 1.4f - 0.2f;
    const glm::vec3 target = tri.v0 + u * (tri.v1 - tri.v0) + v * (tri.v2 - tri.v0);
    const glm::vec3 d = (i & 1) ? target - o : rand_vec(rng, 1);
    const Ray ray(o, d);
    expect_same(ray, tri, 0.0f, kInfinity, c);
    const float seg_lo = 0.5f * uniform(rng);
    const float seg_hi = 0.5f + uniform(rng);
    expect_same(ray, tri, seg_lo, seg_hi, c);
    const Triangle other{rand_vec(rng, 1), rand_vec(rng, 1), rand_vec(rng, 1)};
    pair_lanes += expect_pair_same(ray, (i & 2) ? tri : other, (i & 2) ? other : tri, (i & 4) ? 0.0f : 0.1f);
  }
  EXPECT_GT(c.hits, 30000);
  EXPECT_GT(c.misses, 100000);
  if (bvh_detail::cpu_has_wide8()) {
    EXPECT_EQ(pair_lanes, 8 * 200000);
  }
}

TEST(BvhInlineTriangle, SpecialPathsAgree) {
  std::mt19937 rng(11);
  Counts c;
  const float scales[] = {1e-20f, 1e-12f, 1e-6f, 1.0f, 1e6f, 1e18f, 1e25f};
  for (float s : scales) {
    for (int i = 0; i < 2000; ++i) {
      // A shared edge between two triangles, and a ray through its midpoint
      // or through a shared vertex: edge functions round to exactly zero.
      const glm::vec3 a = rand_vec(rng, s), b = rand_vec(rng, s), p = rand_vec(rng, s), q = rand_vec(rng, s);
      const Triangle t1{a, b, p}, t2{b, a, q};
      const glm::vec3 through = (i % 3 == 0) ? a : 0.5f * (a + b);
      const glm::vec3 o = through + rand_vec(rng, s);
      const Ray ray(o, through - o);
      expect_same(ray, t1, 0.0f, kInfinity, c);
      expect_same(ray, t2, 0.0f, kInfinity, c);
      // Axis-aligned rays (zero direction components) and degenerate triangles.
      glm::vec3 d(0.0f);
      d[i % 3] = (i & 4) ? -1.0f : 1.0f;
      const Ray axis(o, d);
      expect_same(axis, t1, 0.0f, kInfinity, c);
      expect_same(ray, Triangle{a, a, b}, 0.0f, kInfinity, c);
      expect_same(ray, Triangle{a, b, 0.5f * (a + b)}, 0.0f, kInfinity, c);
      expect_pair_same(ray, t1, t2, 0.0f);
      expect_pair_same(ray, t2, Triangle{a, a, b}, 0.0f);
      expect_pair_same(axis, t1, t2, 0.0f);
    }
  }
  // t exactly at the interval ends.
  const Triangle wall{{-1, -1, 2}, {1, -1, 2}, {0, 1, 2}};
  const Ray r({0, 0, 0}, {0, 0, 1});
  expect_same(r, wall, 2.0f, 2.0f, c);
  expect_same(r, wall, 0.0f, 2.0f, c);
  expect_same(r, wall, 2.0f, kInfinity, c);
  expect_same(r, wall, 0.0f, std::nextafter(2.0f, 0.0f), c);
  // Both windings: T against tmin·det on either side of det's sign.
  const Triangle llaw{wall.v0, wall.v2, wall.v1};
  expect_pair_same(r, wall, llaw, 2.0f);
  expect_pair_same(r, llaw, wall, std::nextafter(2.0f, kInfinity));
  EXPECT_GT(c.hits, 1000);
  EXPECT_GT(c.misses, 1000);
}
}  // namespace unity_test_bvh_triangle
