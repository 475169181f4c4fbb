// BVH queries: the SIMD slab tests against their scalar twins, the 4-wide
// collapse, statistics and visit traces, ordered vs unordered traversal,
// any-hit, ids and normals, deep trees, and refitting.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "core/accel/brute_force.h"
#include "core/accel/bvh/bvh.h"
#include "core/accel/bvh/bvh_slab.h"
#include "core/accel/bvh/bvh_wide.h"
#include "tests/core/mt_random.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_bvh_query {

using namespace accelviz;

namespace {

using test_random::random_direction;
using test_random::uniform;

std::vector<Triangle> soup(std::size_t n, std::uint32_t seed, float size = 0.08f) {
  std::mt19937 rng(seed);
  std::vector<Triangle> tris(n);
  for (Triangle& t : tris) {
    const glm::vec3 c{uniform(rng), uniform(rng), uniform(rng)};
    t = {c + size * random_direction(rng), c + size * random_direction(rng), c + size * random_direction(rng)};
  }
  return tris;
}

std::vector<Ray> rays_through_unit_cube(std::size_t n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<Ray> rays;
  for (std::size_t i = 0; i < n; ++i) {
    const glm::vec3 target{uniform(rng), uniform(rng), uniform(rng)};
    const glm::vec3 o = glm::vec3(0.5f) + 2.0f * random_direction(rng);
    rays.emplace_back(o, glm::normalize(target - o));
  }
  return rays;
}

BvhOptions quiet() {
  BvhOptions o;
  o.compute_epo = false;
  return o;
}

bool same_answer(const Hit& a, const Hit& b) {
  if (a.valid() != b.valid()) return false;
  if (!a.valid()) return true;
  return a.prim == b.prim || std::fabs(a.t - b.t) <= 1e-6f * std::max(1.0f, std::fabs(b.t));
}

}  // namespace

// ---- The SIMD slab test and its scalar twin ----

TEST(BvhSlab, SimdAgreesWithScalarTwinOnRandomAndAdversarialInput) {
  std::mt19937 rng(1);
  const float specials[] = {0.0f, -0.0f, 1.0f, -1.0f, 0.5f, kInfinity, -kInfinity, 1e-30f, 1e30f};
  std::size_t checked = 0;
  for (int i = 0; i < 200000; ++i) {
    BvhNode pair[2];
    for (BvhNode& n : pair) {
      glm::vec3 a{uniform(rng), uniform(rng), uniform(rng)}, b{uniform(rng), uniform(rng), uniform(rng)};
      if (i % 5 == 1) b[static_cast<int>(rng() % 3)] = a[static_cast<int>(rng() % 3)];  // flat on some axis
      if (i % 7 == 2) std::swap(a, b);                                                  // possibly empty
      if (i % 11 == 3) a[static_cast<int>(rng() % 3)] = -kInfinity;                     // unbounded
      n.bounds = {glm::min(a, b), glm::max(a, b)};
      if (i % 7 == 2) n.bounds = {a, b};
      n.index = rng();  // garbage in the lane the loads pick up
      n.count = rng() % 2;
    }
    glm::vec3 o{2 * uniform(rng) - 0.5f, 2 * uniform(rng) - 0.5f, 2 * uniform(rng) - 0.5f};
    glm::vec3 d = random_direction(rng);
    for (int a = 0; a < 3; ++a) {
      const unsigned r = rng() % 8;
      if (r == 0) d[a] = (rng() & 1) ? 0.0f : -0.0f;  // axis-parallel
      if (r == 1) o[a] = pair[0].bounds.lo[a];        // on a face plane
      if (r == 2) o[a] = pair[0].bounds.hi[a];
      if (r == 3) d[a] = specials[rng() % 9];
    }
    const Ray ray(o, d, (i % 3 == 0) ? -1.0f : 0.0f, (i % 4 == 0) ? 1.5f : kInfinity);
    const bvh_detail::SlabRay sr(ray);
    float s0[2], s1[2], v0[2], v1[2];
    bool scalar_hit[2];
    for (int c = 0; c < 2; ++c) {
      scalar_hit[c] = bvh_detail::slab_test_scalar(pair[c], ray, ray.tmin, ray.tmax, s0[c], s1[c]);
      float t0, t1;
      const bool simd_hit = bvh_detail::slab_test(pair[c], sr, ray.tmin, ray.tmax, t0, t1);
      ASSERT_EQ(simd_hit, scalar_hit[c]) << "case " << i;
      // Equal values (+0 and -0 may differ in sign, which no comparison sees).
      ASSERT_TRUE(t0 == s0[c] || (std::isnan(t0) && std::isnan(s0[c])))
          << "case " << i << ": " << t0 << " vs " << s0[c];
      ASSERT_TRUE(t1 == s1[c] || (std::isnan(t1) && std::isnan(s1[c])))
          << "case " << i << ": " << t1 << " vs " << s1[c];
    }
    const int mask = bvh_detail::slab_test_pair(pair, sr, ray.tmin, ray.tmax, v0, v1);
    ASSERT_EQ(mask, (scalar_hit[0] ? 1 : 0) | (scalar_hit[1] ? 2 : 0)) << "case " << i;
    for (int c = 0; c < 2; ++c) {
      ASSERT_TRUE(v0[c] == s0[c] || (std::isnan(v0[c]) && std::isnan(s0[c]))) << "case " << i;
      ASSERT_TRUE(v1[c] == s1[c] || (std::isnan(v1[c]) && std::isnan(s1[c]))) << "case " << i;
    }
    ++checked;
  }
  EXPECT_EQ(checked, 200000u);
}

TEST(BvhSlab, RayInAFacePlaneTouchesTheBox) {
  BvhNode n;
  n.bounds = {glm::vec3(0), glm::vec3(1)};
  const Ray along_face({-1.0f, 0.0f, 0.5f}, {1.0f, 0.0f, 0.0f});  // y = lo.y exactly, dy = +0
  const bvh_detail::SlabRay sr(along_face);
  float t0, t1;
  EXPECT_TRUE(bvh_detail::slab_test(n, sr, 0.0f, kInfinity, t0, t1));
  EXPECT_EQ(t0, 1.0f);
  const Ray beside({-1.0f, -0.001f, 0.5f}, {1.0f, 0.0f, 0.0f});
  EXPECT_FALSE(bvh_detail::slab_test(n, bvh_detail::SlabRay(beside), 0.0f, kInfinity, t0, t1));
}

/// A wide node of random boxes in the unit cube for the box-test checks,
/// flat ones (an axis of zero extent) in every fifth case `i`; slot s gets
/// Aabb::empty() where empty_box(s), and is marked unused (kWideEmpty) where
/// empty_slot(s).
template <int W, class EmptyBox, class EmptySlot>
bvh_detail::WideNodeT<W> random_wide_node(std::mt19937& rng, int i, const EmptyBox& empty_box,
                                          const EmptySlot& empty_slot) {
  bvh_detail::WideNodeT<W> n;
  for (int s = 0; s < W; ++s) {
    glm::vec3 a{uniform(rng), uniform(rng), uniform(rng)}, b{uniform(rng), uniform(rng), uniform(rng)};
    if (i % 5 == 1) b[static_cast<int>(rng() % 3)] = a[static_cast<int>(rng() % 3)];
    Aabb box{glm::min(a, b), glm::max(a, b)};
    if (empty_box(s)) box = Aabb::empty();
    for (int r = 0; r < 3; ++r) {
      n.bounds[r][s] = box.lo[r];
      n.bounds[3 + r][s] = box.hi[r];
    }
    n.child[s] = rng();
    n.meta[s] = empty_slot(s) ? bvh_detail::kWideEmpty : rng() % 5;
  }
  return n;
}

TEST(BvhSlab, WideTestAgreesWithScalarTwinPerSlot) {
  std::mt19937 rng(2);
  const float specials[] = {0.0f, -0.0f, 1.0f, -1.0f, kInfinity, -kInfinity, 1e-30f};
  for (int i = 0; i < 100000; ++i) {
    const auto n = random_wide_node<4>(
        rng, i, [&](int s) { return i % 7 == 2 && s == 1; }, [&](int s) { return i % 9 == 4 && s == 3; });
    glm::vec3 o{2 * uniform(rng) - 0.5f, 2 * uniform(rng) - 0.5f, 2 * uniform(rng) - 0.5f};
    glm::vec3 d = random_direction(rng);
    for (int a = 0; a < 3; ++a) {
      const unsigned r = rng() % 8;
      if (r == 0) d[a] = (rng() & 1) ? 0.0f : -0.0f;
      if (r == 1) o[a] = n.bounds[a][0];  // on a face plane of slot 0
      if (r == 2) d[a] = specials[rng() % 7];
    }
    const Ray ray(o, d, (i % 3 == 0) ? -1.0f : 0.0f, (i % 4 == 0) ? 1.5f : kInfinity);
    float se[4], sx[4], ve[4], vx[4];
    int scalar = bvh_detail::wide_slab_test_scalar(n, ray, ray.tmin, ray.tmax, se, sx);
    for (int s = 0; s < 4; ++s)
      if (n.meta[s] == bvh_detail::kWideEmpty) scalar &= ~(1 << s);
    const int simd = bvh_detail::wide_slab_test(n, bvh_detail::WideSlabRay(ray), ray.tmin, ray.tmax, ve, vx);
    ASSERT_EQ(simd, scalar) << "case " << i;
    for (int s = 0; s < 4; ++s) {
      // Same operations in the same order: bit-identical per slot.
      ASSERT_EQ(std::memcmp(&ve[s], &se[s], 4), 0) << "case " << i << " slot " << s;
      ASSERT_EQ(std::memcmp(&vx[s], &sx[s], 4), 0) << "case " << i << " slot " << s;
    }
  }
}

#ifdef ACCELVIZ_BVH_WIDE8_AVX2
// The AVX2 test inlines only into AVX2 code (called when the CPU has it).
[[gnu::target("avx2")]] int wide8_slab_test(const bvh_detail::WideNode8& n, const Ray& ray, float* te, float* tx) {
  return bvh_detail::wide_slab_test8(n, bvh_detail::WideSlabRay8(ray), ray.tmin, ray.tmax, te, tx);
}

TEST(BvhSlab, EightWideAvx2TestAgreesWithScalarTwinPerSlot) {
  if (!bvh_detail::cpu_has_wide8()) GTEST_SKIP() << "this CPU has no AVX2";
  std::mt19937 rng(8);
  const float specials[] = {0.0f, -0.0f, 1.0f, -1.0f, kInfinity, -kInfinity, 1e-30f};
  for (int i = 0; i < 50000; ++i) {
    const auto n = random_wide_node<8>(
        rng, i, [&](int s) { return i % 7 == 2 && s == 5; }, [&](int s) { return i % 9 == 4 && s >= 6; });
    glm::vec3 o{2 * uniform(rng) - 0.5f, 2 * uniform(rng) - 0.5f, 2 * uniform(rng) - 0.5f};
    glm::vec3 d = random_direction(rng);
    for (int a = 0; a < 3; ++a) {
      const unsigned r = rng() % 8;
      if (r == 0) d[a] = (rng() & 1) ? 0.0f : -0.0f;
      if (r == 1) o[a] = n.bounds[a][3];  // on a face plane of slot 3
      if (r == 2) d[a] = specials[rng() % 7];
    }
    const Ray ray(o, d, (i % 3 == 0) ? -1.0f : 0.0f, (i % 4 == 0) ? 1.5f : kInfinity);
    float se[8], sx[8];
    alignas(32) float ve[8], vx[8];
    int scalar = bvh_detail::wide_slab_test_scalar<8>(n, ray, ray.tmin, ray.tmax, se, sx);
    for (int s = 0; s < 8; ++s)
      if (n.meta[s] == bvh_detail::kWideEmpty) scalar &= ~(1 << s);
    const int simd = wide8_slab_test(n, ray, ve, vx);
    ASSERT_EQ(simd, scalar) << "case " << i;
    for (int s = 0; s < 8; ++s) {
      ASSERT_EQ(std::memcmp(&ve[s], &se[s], 4), 0) << "case " << i << " slot " << s;
      ASSERT_EQ(std::memcmp(&vx[s], &sx[s], 4), 0) << "case " << i << " slot " << s;
    }
  }
}

[[gnu::target("avx2,fma")]] int wide8_fast_slab_test(const bvh_detail::WideNode8& n, const Ray& ray, float* te,
                                                     float* tx, bool& fast) {
  const bvh_detail::WideSlabRay8 r(ray);
  fast = r.fast;
  return bvh_detail::wide_slab_test8_fast(n, r, ray.tmax, te, tx);
}

// The walk's shorter box test (wide_slab_test8_fast) against the scalar
// test, on the rays it is used for: every box the scalar test hits, with an
// entry no later and an exit no earlier, both within a few ulps (or, for an
// origin far from the box, within the origin pad); more boxes only where
// the scalar entry and exit lie that close; empty slots missed without
// their mask. And the rays it must not take.
TEST(BvhSlab, EightWideFastTestHoldsToTheScalarTest) {
  if (!bvh_detail::cpu_has_wide8()) GTEST_SKIP() << "this CPU has no AVX2 and FMA";
  std::mt19937 rng(81);
  const float specials[] = {1.0f, -1.0f, 1e-30f, -1e-30f, 1e30f, 2e-39f, 0.5f};
  int hits = 0, near_tie_extras = 0, touches_at_zero = 0, zero_tmax_hits = 0, taken = 0, shifted = 0;
  for (int i = 0; i < 50000; ++i) {
    const auto empty = [&](int s) { return i % 7 == 2 && s >= 5; };  // box and slot
    auto n = random_wide_node<8>(rng, i, empty, empty);
    glm::vec3 o{2 * uniform(rng) - 0.5f, 2 * uniform(rng) - 0.5f, 2 * uniform(rng) - 0.5f};
    // Boxes and origin far from 0: origin · inv_dir is large next to the
    // boxes' distances, so the pad on its rounding is what keeps them.
    const float shift = i % 6 == 5 ? 4096.0f : 0.0f;
    for (int s = 0; s < 8 && shift != 0.0f; ++s)
      if (std::isfinite(n.bounds[0][s]))
        for (int r = 0; r < 6; ++r) n.bounds[r][s] += shift;
    o += glm::vec3(shift);
    // An origin near 0 in front of the boxes: c is tiny, its pad too, and
    // the near scale must cover the rounding of plane − origin alone.
    if (i % 6 == 4) o *= -1e-3f;
    glm::vec3 d = random_direction(rng);
    for (int a = 0; a < 3; ++a) {
      const unsigned r = rng() % 8;
      if (r == 1) o[a] = n.bounds[a][3];      // on a face plane of slot 3
      if (r == 2) o[a] = n.bounds[3 + a][4];  // on a face plane of slot 4
      if (r == 3) d[a] = specials[rng() % 7];
    }
    const float tmin = (i % 3 == 0) ? 0.25f : (i % 3 == 1 ? 0.0f : -0.0f);
    const float tmax = (i % 4 == 0) ? 1.5f : (i % 11 == 3 ? -0.0f : kInfinity);  // [0, -0]: touches at 0
    const Ray ray(o, d, tmin, tmax);
    float se[8], sx[8];
    alignas(32) float fe[8], fx[8];
    const int scalar = bvh_detail::wide_slab_test_scalar<8>(n, ray, ray.tmin, ray.tmax, se, sx);
    bool fast = false;
    const int mask = wide8_fast_slab_test(n, ray, fe, fx, fast);
    if (!fast) {
      // Only a direction component so small (2e-39) that its inverse
      // overflows keeps these rays off the fast test.
      ASSERT_TRUE(std::isinf(ray.inv_dir.x) || std::isinf(ray.inv_dir.y) || std::isinf(ray.inv_dir.z)) << "case " << i;
      continue;
    }
    ++taken;
    shifted += shift != 0.0f ? 1 : 0;
    // The distances may move by a few ulps and by the pad on origin · inv.
    float pad = 0.0f;
    for (int a = 0; a < 3; ++a) pad = std::max(pad, std::fabs(ray.origin[a] * ray.inv_dir[a]) * 0x1p-20f);
    const auto close = [&](float t0, float t1) {
      return std::fabs(t0 - t1) <= 0x1p-17f * std::max(std::fabs(t0), std::fabs(t1)) + pad;
    };
    for (int s = 0; s < 8; ++s) {
      const bool f = (mask >> s) & 1;
      if (n.meta[s] == bvh_detail::kWideEmpty) {
        ASSERT_FALSE(f) << "case " << i << " slot " << s << ": an empty slot hit";
        continue;
      }
      const bool e = (scalar >> s) & 1;
      if (e) {
        ++hits;
        ASSERT_TRUE(f) << "case " << i << " slot " << s << ": a box the scalar test hits missed";
        ASSERT_LE(fe[s], se[s]) << "case " << i << " slot " << s;
        ASSERT_TRUE(close(fe[s], se[s])) << "case " << i << " slot " << s << ": " << fe[s] << " " << se[s];
        if (std::isfinite(sx[s])) {
          ASSERT_GE(fx[s], sx[s]) << "case " << i << " slot " << s;
          ASSERT_TRUE(close(fx[s], sx[s])) << "case " << i << " slot " << s << ": " << fx[s] << " " << sx[s];
        }
      } else if (f) {
        ASSERT_TRUE(close(se[s], sx[s])) << "case " << i << " slot " << s << ": " << se[s] << " " << sx[s] << " "
                                         << fx[s];
        ++near_tie_extras;
      }
      // The integer compare needs an exit that is never −0.
      ASSERT_FALSE(fx[s] == 0.0f && std::signbit(fx[s])) << "case " << i << " slot " << s;
      zero_tmax_hits += e && ray.tmax == 0.0f ? 1 : 0;
      touches_at_zero += e && sx[s] == 0.0f ? 1 : 0;
    }
  }
  EXPECT_GT(taken, 45000);
  EXPECT_LT(taken, 50000);  // the 2e-39 components reach the exact test's side
  EXPECT_GT(shifted, 7000);
  EXPECT_GT(hits, 10000);
  EXPECT_LT(near_tie_extras, 100);
  EXPECT_GT(touches_at_zero, 0);  // origins on far planes: intersect_slab's exit ±0, kept
  EXPECT_GT(zero_tmax_hits, 0);   // boxes around the origin kept by a ray [0, -0]
}

// An origin a subnormal step beyond a box's far plane, with a direction
// that scales the step below the smallest subnormal: intersect_slab rounds
// the exit to -0 and keeps the box (entry +0 <= -0); the fast test must keep
// it too, with a positive exit (its integer compare would drop a -0).
TEST(BvhSlab, EightWideFastTestKeepsABoxWhoseExitRoundsToMinusZero) {
  if (!bvh_detail::cpu_has_wide8()) GTEST_SKIP() << "this CPU has no AVX2 and FMA";
  bvh_detail::WideNode8 n;
  for (int s = 0; s < 8; ++s) {
    const Aabb box = s == 0 ? Aabb{{-1.0f, -1.0f, -1.0f}, {1e-40f, 1.0f, 1.0f}} : Aabb::empty();
    for (int r = 0; r < 3; ++r) {
      n.bounds[r][s] = box.lo[r];
      n.bounds[3 + r][s] = box.hi[r];
    }
    n.child[s] = 0;
    n.meta[s] = s == 0 ? 1u : bvh_detail::kWideEmpty;
  }
  const float ox = std::nextafter(1e-40f, 1.0f);  // one subnormal step beyond x = 1e-40
  const Ray ray({ox, 0.0f, 0.0f}, {4.0f, 0.5f, 0.25f}, 0.0f, kInfinity);
  float se[8], sx[8];
  alignas(32) float fe[8], fx[8];
  const int scalar = bvh_detail::wide_slab_test_scalar<8>(n, ray, ray.tmin, ray.tmax, se, sx);
  ASSERT_EQ(scalar & 1, 1);
  ASSERT_TRUE(sx[0] == 0.0f && std::signbit(sx[0])) << sx[0];  // the case this test is about
  bool fast = false;
  const int mask = wide8_fast_slab_test(n, ray, fe, fx, fast);
  ASSERT_TRUE(fast);
  EXPECT_EQ(mask & 1, 1);
  EXPECT_GT(fx[0], 0.0f);
}

TEST(BvhSlab, EightWideFastTestIsNotTakenByRaysItCouldGetWrong) {
  if (!bvh_detail::cpu_has_wide8()) GTEST_SKIP() << "this CPU has no AVX2";
  const auto fast = [](const Ray& r) { return bvh_detail::WideSlabRay8(r).fast; };
  const glm::vec3 o(0.5f, 0.5f, 0.5f);
  EXPECT_TRUE(fast(Ray(o, {1, 2, 3}, 0.0f, kInfinity)));
  EXPECT_TRUE(fast(Ray(o, {1, 2, 3}, -0.0f, 1.0f)));
  EXPECT_FALSE(fast(Ray(o, {0.0f, 2, 3}, 0.0f, kInfinity)));    // 0 · inf in a face plane
  EXPECT_FALSE(fast(Ray(o, {1, -0.0f, 3}, 0.0f, kInfinity)));   // -0 direction
  EXPECT_FALSE(fast(Ray(o, {1, 2, 1e-39f}, 0.0f, kInfinity)));  // 1/d past the largest float
  EXPECT_FALSE(fast(Ray({kInfinity, 0, 0}, {1, 2, 3}, 0.0f, kInfinity)));
  EXPECT_TRUE(fast(Ray({1e20f, 0, 0}, {1, 2, 3}, 0.0f, kInfinity)));
  EXPECT_FALSE(fast(Ray({1e30f, 0, 0}, {1e-10f, 2, 3}, 0.0f, kInfinity)));  // origin · inv_dir past the largest float
  EXPECT_FALSE(fast(Ray(o, {1, 2, 3}, -1.0f, kInfinity)));  // negative tmin: integers order negatives backwards
  EXPECT_FALSE(fast(Ray(o, {1, 2, 3}, std::numeric_limits<float>::quiet_NaN(), kInfinity)));
  EXPECT_FALSE(fast(Ray(o, {1, 2, 3}, 0.0f, std::numeric_limits<float>::quiet_NaN())));
  EXPECT_FALSE(fast(Ray(o, {1, 2, 3}, 0.0f, -1e-45f)));  // negative tmax: the exit's pad would wrap around
  EXPECT_TRUE(fast(Ray(o, {1, 2, 3}, 0.0f, -0.0f)));
}
#endif

TEST(BvhWide, EightWideCollapseKeepsEveryLeafOnceAndRefitsWithTheBinaryTree) {
  const auto tris = soup(3000, 31);
  const Bvh bvh(tris, quiet());
  const auto nodes = bvh.nodes();
  bvh_detail::WideBvh8 wide;
  bvh_detail::collapse_to_wide(nodes, wide);
  ASSERT_EQ(wide.source.size(), 8 * wide.nodes.size());
  std::vector<int> leaf_seen(nodes.size(), 0);
  std::size_t used_slots = 0;
  for (std::size_t w = 0; w < wide.nodes.size(); ++w)
    for (int s = 0; s < 8; ++s) {
      const bvh_detail::WideNode8& n = wide.nodes[w];
      if (n.meta[s] == bvh_detail::kWideEmpty) continue;
      ++used_slots;
      const std::uint32_t src = wide.source[8 * w + s];
      ASSERT_LT(src, nodes.size());
      EXPECT_EQ(n.bounds[3][s], nodes[src].bounds.hi.x);
      if (n.meta[s] == 0) {
        ASSERT_GT(n.child[s], w);
      } else {
        EXPECT_EQ(n.meta[s], nodes[src].count);
        ++leaf_seen[src];
      }
    }
  for (std::size_t i = 0; i < nodes.size(); ++i) EXPECT_EQ(leaf_seen[i], nodes[i].count > 0 ? 1 : 0) << i;
  // Every wide node but the root is one slot of its parent: slots = nodes - 1 + leaves.
  const auto leaves =
      static_cast<std::size_t>(std::count_if(nodes.begin(), nodes.end(), [](const BvhNode& n) { return n.count > 0; }));
  EXPECT_EQ(used_slots, wide.nodes.size() - 1 + leaves);
  // Fewer, fuller nodes than the 4-wide collapse of the same tree (the same
  // count of slots: every binary leaf plus one per non-root wide node).
  const std::size_t four = bvh_detail::collapse_to_wide(nodes).nodes.size();
  EXPECT_LT(wide.nodes.size(), four);
  EXPECT_GT(static_cast<double>(used_slots) / wide.nodes.size(), static_cast<double>(four - 1 + leaves) / four);
  // A refit copies moved binary boxes into the slots.
  std::vector<BvhNode> moved(nodes.begin(), nodes.end());
  for (BvhNode& n : moved) n.bounds.hi += glm::vec3(1.0f);
  bvh_detail::refit_wide(wide, moved);
  for (std::size_t w = 0; w < wide.nodes.size(); ++w)
    for (int s = 0; s < 8; ++s)
      if (wide.source[8 * w + s] != bvh_detail::kWideEmpty) {
        EXPECT_EQ(wide.nodes[w].bounds[5][s], moved[wide.source[8 * w + s]].bounds.hi.z);
      }
}

TEST(BvhWide, EveryWidthAnswersLikeTheBinaryTree) {
  const auto tris = soup(2000, 32);
  BvhOptions binary_opts = quiet();
  binary_opts.wide_traversal = false;
  const Bvh binary(tris, binary_opts);
  std::mt19937 rng(33);
  for (int width : {0, 4, 8}) {
    BvhOptions o = quiet();
    o.wide_width = width;
    const Bvh bvh(tris, o);
    const double expect = width == 4 || !bvh_detail::cpu_has_wide8() ? 4.0 : 8.0;
    EXPECT_EQ(bvh.build_stats().extra.at("wide_width"), expect) << width;
    for (int i = 0; i < 20000; ++i) {
      const glm::vec3 orig{2 * uniform(rng) - 0.5f, 2 * uniform(rng) - 0.5f, 2 * uniform(rng) - 0.5f};
      const Ray ray(orig, random_direction(rng));
      for (bool ordered : {true, false}) {
        QueryOptions q;
        q.ordered = ordered;
        const Hit a = binary.closest_hit(ray, q), b = bvh.closest_hit(ray, q);
        ASSERT_EQ(a.prim, b.prim) << "width " << width << " ray " << i;
        ASSERT_EQ(a.t, b.t);
        ASSERT_EQ(binary.any_hit(ray, q), bvh.any_hit(ray, q));
      }
    }
  }
  BvhOptions bad = quiet();
  bad.wide_width = 6;
  EXPECT_THROW(Bvh(tris, bad), std::invalid_argument);
}

#ifdef ACCELVIZ_NO_SIMD
// The nosimd preset (scripts/test.sh): every test of this build runs the
// scalar twins, so the SIMD paths must really be compiled out, in the tests'
// headers and in the core library (cpu_has_wide8 is compiled there).
TEST(BvhWide, ScalarBuildHasNoSimdPath) {
#if defined(ACCELVIZ_BVH_TRI4_SSE2) || defined(ACCELVIZ_BVH_WIDE8_AVX2)
  FAIL() << "ACCELVIZ_NO_SIMD is defined but a SIMD path is compiled in";
#endif
  EXPECT_FALSE(bvh_detail::cpu_has_wide8());
  BvhOptions o = quiet();
  o.wide_width = 8;
  EXPECT_EQ(Bvh(soup(100, 7), o).build_stats().extra.at("wide_width"), 4.0);
}
#endif

TEST(BvhWide, CollapseKeepsEveryLeafOnceWithItsBox) {
  for (int leaf : {1, 4}) {
    const auto tris = soup(3000, 20 + leaf);
    BvhOptions o = quiet();
    o.max_leaf_size = leaf;
    const Bvh bvh(tris, o);
    const auto nodes = bvh.nodes();
    const bvh_detail::WideBvh wide = bvh_detail::collapse_to_wide(nodes);
    ASSERT_EQ(wide.source.size(), 4 * wide.nodes.size());
    std::vector<int> leaf_seen(nodes.size(), 0);
    std::vector<int> wide_parents(wide.nodes.size(), 0);
    for (std::size_t w = 0; w < wide.nodes.size(); ++w) {
      int used = 0;
      for (int s = 0; s < 4; ++s) {
        const std::uint32_t src = wide.source[4 * w + s];
        const bvh_detail::WideNode& n = wide.nodes[w];
        if (n.meta[s] == bvh_detail::kWideEmpty) {
          EXPECT_EQ(src, bvh_detail::kWideEmpty);
          continue;
        }
        ++used;
        ASSERT_LT(src, nodes.size());
        const Aabb& b = nodes[src].bounds;
        EXPECT_EQ(n.bounds[0][s], b.lo.x);
        EXPECT_EQ(n.bounds[4][s], b.hi.y);
        EXPECT_EQ(n.bounds[5][s], b.hi.z);
        if (n.meta[s] == 0) {
          ASSERT_GT(n.child[s], w);  // wide children after their parent
          ASSERT_LT(n.child[s], wide.nodes.size());
          ++wide_parents[n.child[s]];
          EXPECT_EQ(nodes[src].count, 0u);
        } else {
          EXPECT_EQ(n.meta[s], nodes[src].count);
          EXPECT_EQ(n.child[s], nodes[src].index);
          ++leaf_seen[src];
        }
      }
      EXPECT_GE(used, 2);
    }
    for (std::size_t i = 0; i < nodes.size(); ++i) EXPECT_EQ(leaf_seen[i], nodes[i].count > 0 ? 1 : 0) << i;
    for (std::size_t w = 1; w < wide.nodes.size(); ++w) EXPECT_EQ(wide_parents[w], 1);
    // Mostly full nodes: each wide node takes about two binary inner nodes
    // (binary nodes / 4 would be exactly two; the box-centre tree of this
    // soup measured 0.251 at leaf 1).
    EXPECT_LT(wide.nodes.size(), nodes.size() * 26 / 100);
  }
}

TEST(BvhWide, SingleLeafTreeCollapsesToOneSlot) {
  const std::vector<Triangle> tris(3, Triangle{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  const Bvh bvh(tris, quiet());
  const bvh_detail::WideBvh wide = bvh_detail::collapse_to_wide(bvh.nodes());
  ASSERT_EQ(wide.nodes.size(), 1u);
  EXPECT_EQ(wide.nodes[0].meta[0], 3u);
  EXPECT_EQ(wide.nodes[0].meta[1], bvh_detail::kWideEmpty);
  EXPECT_TRUE(bvh.any_hit(Ray({0.2f, 0.2f, -1}, {0, 0, 1}), {}));
  EXPECT_TRUE(bvh_detail::collapse_to_wide({}).nodes.empty());
}

// ---- Basic answers ----

TEST(BvhQuery, SingleTriangleHitAndMiss) {
  const std::vector<Triangle> one = {{{-1, -1, 5}, {1, -1, 5}, {0, 1, 5}}};
  const Bvh bvh(one, quiet());
  const Hit h = bvh.closest_hit(Ray({0, 0, 0}, {0, 0, 1}), {});
  ASSERT_TRUE(h.valid());
  EXPECT_EQ(h.prim, 0u);
  EXPECT_FLOAT_EQ(h.t, 5.0f);
  EXPECT_FLOAT_EQ(std::fabs(h.ng.z), 1.0f);
  EXPECT_FALSE(bvh.closest_hit(Ray({0, 0, 0}, {0, 0, -1}), {}).valid());
  EXPECT_FALSE(bvh.closest_hit(Ray({0, 0, 0}, {0, 0, 1}, 0.0f, 4.9f), {}).valid());  // segment ends before
  EXPECT_FALSE(bvh.closest_hit(Ray({0, 0, 0}, {0, 0, 1}, 5.1f), {}).valid());        // starts after
  EXPECT_TRUE(bvh.any_hit(Ray({0, 0, 0}, {0, 0, 1}), {}));
  EXPECT_FALSE(bvh.any_hit(Ray({3, 0, 0}, {0, 0, 1}), {}));
}

TEST(BvhQuery, ReportsSceneIdsAndNormalsOfTheSceneTriangles) {
  // Two parallel layers; ids must come back in scene order whatever the leaf order.
  const auto tris = soup(2000, 3);
  const Bvh bvh(tris, quiet());
  const BruteForce bf(tris);
  for (const Ray& r : rays_through_unit_cube(2000, 4)) {
    const Hit h = bvh.closest_hit(r, {});
    const Hit ref = bf.closest_hit(r, {});
    ASSERT_TRUE(same_answer(h, ref));
    if (!h.valid()) continue;
    EXPECT_EQ(h.ng, triangle_normal(tris[h.prim]));
    if (h.prim == ref.prim) {
      EXPECT_EQ(h.u, ref.u);
      EXPECT_EQ(h.v, ref.v);
    }
    EXPECT_EQ(h.instance, kInvalidId);
  }
}

TEST(BvhQuery, NameIsBvh) {
  const std::vector<Triangle> none;
  EXPECT_EQ(Bvh(none).name(), "bvh");
}

// ---- Statistics and traces ----

TEST(BvhQuery, StatisticsAgreeWithTheVisitTrace) {
  const auto tris = soup(3000, 5);
  const Bvh bvh(tris, quiet());
  std::size_t culled_total = 0;
  for (bool ordered : {true, false}) {
    QueryOptions q;
    q.ordered = ordered;
    for (const Ray& r : rays_through_unit_cube(1000, 6)) {
      RayStats st;
      VisitTrace tr;
      const Hit h = bvh.closest_hit(r, q, &st, &tr);
      std::uint32_t entered = 0, missed = 0, culled = 0, tested = 0, inner_entered = 0;
      float best = kInfinity;
      for (const VisitStep& s : tr.steps) {
        switch (s.kind) {
          case VisitStep::Kind::node_entered:
            ++entered;
            ASSERT_LT(s.id, bvh.nodes().size());
            if (bvh.nodes()[s.id].count == 0) ++inner_entered;
            EXPECT_LE(s.t_entry, s.t_exit);
            EXPECT_LE(s.t_entry, best);  // never entered beyond the closest hit found so far
            break;
          case VisitStep::Kind::node_missed:
            ++missed;
            break;
          case VisitStep::Kind::node_culled:
            ++culled;
            EXPECT_GT(s.t_entry, best);  // culled: its entry lies beyond the closest hit so far
            EXPECT_GT(s.t_entry, h.t);
            break;
          case VisitStep::Kind::prim_hit:
            ++tested;
            ASSERT_LT(s.id, tris.size());
            best = std::min(best, s.t_entry);
            break;
          case VisitStep::Kind::prim_miss:
            ++tested;
            EXPECT_EQ(s.t_entry, kInfinity);
            break;
        }
      }
      EXPECT_EQ(st.nodes_visited, entered);
      EXPECT_EQ(st.nodes_missed, missed);
      EXPECT_EQ(st.nodes_culled, culled);
      EXPECT_EQ(st.prim_tests, tested);
      EXPECT_EQ(st.box_tests, 1 + 2 * inner_entered);  // the root, then both children of every inner node entered
      EXPECT_EQ(st.repeated_prim_tests, 0u);           // a BVH references each primitive once
      EXPECT_EQ(h.valid() ? h.t : kInfinity, best);    // the closest of the hits recorded
      culled_total += culled;
      // Stats alone, trace alone: same answer.
      RayStats only;
      EXPECT_EQ(bvh.closest_hit(r, q, &only).prim, h.prim);
      EXPECT_EQ(only.nodes_visited, st.nodes_visited);
      VisitTrace only_trace;
      EXPECT_EQ(bvh.closest_hit(r, q, nullptr, &only_trace).prim, h.prim);
      EXPECT_EQ(only_trace.steps.size(), tr.steps.size());
    }
  }
  EXPECT_GT(culled_total, 0u);
}

// The heatmap's counted walk (closest hit with statistics and no trace, one
// ray or several in turns) against the instrumented walk a trace takes: the
// same hit to the bit and the same counters, ray by ray, on tree shapes with
// one and several triangle blocks per leaf, both triangle tests, ordered and
// not, and rays that miss, start inside, run along axes or end early.
TEST(BvhQuery, CountedWalkMatchesTheTracedWalkPerRay) {
  const auto tris = soup(1500, 11);
  std::vector<Ray> rays = rays_through_unit_cube(600, 12);
  std::mt19937 rng(13);
  for (int i = 0; i < 150; ++i) {
    const glm::vec3 inside{uniform(rng), uniform(rng), uniform(rng)};
    rays.emplace_back(inside, random_direction(rng));                                      // starts inside
    rays.emplace_back(glm::vec3(inside.x, inside.y, -1.0f), glm::vec3(0.0f, 0.0f, 1.0f));  // along +z: ±0 components
    rays.emplace_back(glm::vec3(-1.0f, inside.y, inside.z), glm::vec3(1.0f, 0.0f, 0.0f), 0.5f, 1.0f + inside.x);
    rays.emplace_back(glm::vec3(3.0f, 3.0f, 3.0f) + inside, random_direction(rng));  // mostly misses
  }
  auto same_bits = [](float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; };
  std::size_t hits = 0, culled = 0;
  for (int shape = 0; shape < 3; ++shape) {
    BvhOptions o = quiet();
    if (shape == 1) o.max_leaf_size = 1;
    if (shape == 2) {
      o.max_leaf_size = 11;  // leaves of up to three blocks, the last one partly padding
      o.leaf_size_cap = 11;
      o.splitter = BvhSplitter::median;
    }
    const Bvh bvh(tris, o);
    for (const TriangleTest test : {TriangleTest::watertight, TriangleTest::moller_trumbore})
      for (const bool ordered : {true, false}) {
        QueryOptions q;
        q.triangle_test = test;
        q.ordered = ordered;
        std::vector<Hit> batch_hits(rays.size());
        std::vector<RayStats> batch_stats(rays.size());
        for (RayStats& st : batch_stats) st.nodes_visited = 7;  // the counters are added, as closest_hit does
        bvh.closest_hits(rays, batch_hits, q, batch_stats);
        for (std::size_t i = 0; i < rays.size(); ++i) {
          RayStats ref, one;
          VisitTrace trace;
          const Hit h_ref = bvh.closest_hit(rays[i], q, &ref, &trace);
          const Hit h_one = bvh.closest_hit(rays[i], q, &one);
          RayStats batch = batch_stats[i];
          batch.nodes_visited -= 7;
          for (const auto& [got, h] : {std::pair{one, h_one}, std::pair{batch, batch_hits[i]}}) {
            ASSERT_EQ(got.nodes_visited, ref.nodes_visited) << "shape " << shape << " ray " << i;
            EXPECT_EQ(got.box_tests, ref.box_tests);
            EXPECT_EQ(got.prim_tests, ref.prim_tests);
            EXPECT_EQ(got.nodes_culled, ref.nodes_culled);
            EXPECT_EQ(got.nodes_missed, ref.nodes_missed);
            EXPECT_EQ(got.leaves_skipped, 0u);
            EXPECT_EQ(h.prim, h_ref.prim);
            EXPECT_TRUE(same_bits(h.t, h_ref.t) && same_bits(h.u, h_ref.u) && same_bits(h.v, h_ref.v));
            EXPECT_TRUE(same_bits(h.ng.x, h_ref.ng.x) && same_bits(h.ng.y, h_ref.ng.y) &&
                        same_bits(h.ng.z, h_ref.ng.z));
          }
          hits += h_ref.valid();
          culled += ref.nodes_culled;
        }
      }
  }
  EXPECT_GT(hits, 1000u);  // the comparison covers hits, misses and culling
  EXPECT_GT(culled, 1000u);
  const Bvh empty(std::vector<Triangle>{}, quiet());
  std::vector<Hit> h(1);
  std::vector<RayStats> st(1);
  empty.closest_hits(std::span(rays).first(1), h, {}, st);
  EXPECT_FALSE(h[0].valid());
  EXPECT_EQ(st[0].box_tests, 0u);
  std::vector<Hit> two(2);
  EXPECT_THROW(empty.closest_hits(std::span(rays).first(1), two, {}, st), std::invalid_argument);
}

TEST(BvhQuery, OrderedTraversalVisitsFewerNodes) {
  const auto tris = soup(5000, 7, 0.03f);
  const Bvh bvh(tris, quiet());
  RayStats ordered, unordered;
  QueryOptions q;
  for (const Ray& r : rays_through_unit_cube(3000, 8)) {
    q.ordered = true;
    const Hit a = bvh.closest_hit(r, q, &ordered);
    q.ordered = false;
    const Hit b = bvh.closest_hit(r, q, &unordered);
    ASSERT_TRUE(same_answer(a, b));
  }
  EXPECT_LT(ordered.nodes_visited, unordered.nodes_visited);
  EXPECT_LT(ordered.prim_tests, unordered.prim_tests);
  EXPECT_GT(ordered.nodes_culled, 0u);
}

TEST(BvhQuery, AnyHitStopsAtTheFirstHit) {
  const auto tris = soup(5000, 9, 0.03f);
  const Bvh bvh(tris, quiet());
  RayStats closest, any;
  std::size_t hits = 0;
  for (const Ray& r : rays_through_unit_cube(2000, 10)) {
    const bool c = bvh.closest_hit(r, {}, &closest).valid();
    RayStats one;
    const bool a = bvh.any_hit(r, {}, &one);
    any += one;
    ASSERT_EQ(a, c);
    hits += a;
    EXPECT_EQ(one.nodes_culled, 0u);  // nothing to cull without a closest hit
  }
  EXPECT_GT(hits, 500u);
  EXPECT_LT(any.prim_tests, closest.prim_tests);
  EXPECT_LT(any.nodes_visited, closest.nodes_visited);
}

TEST(BvhQuery, TraversalOfATreeAtTheDepthBudget) {
  // Exponentially spaced slivers drive a two-bucket build to the depth budget;
  // the fixed traversal stack must still hold.
  std::vector<Triangle> tris;
  for (int i = 0; i < 400; ++i) {
    const float x = std::ldexp(1.0f, i / 4 - 60) * (1.0f + 0.25f * static_cast<float>(i % 4));
    tris.push_back({{x, -1, -1}, {x, 1, -1}, {x, 0, 1}});
  }
  BvhOptions o = quiet();
  o.buckets = 2;
  o.max_leaf_size = 1;
  o.leaf_size_cap = 1;
  const Bvh bvh(tris, o);
  EXPECT_GT(bvh.build_stats().max_depth, 40u);
  const BruteForce bf(tris);
  std::mt19937 rng(11);
  for (int i = 0; i < 2000; ++i) {
    // From the far end back toward 0, through the dense region.
    const float x0 = std::ldexp(1.0f, static_cast<int>(rng() % 40));
    const Ray r{{x0, 0.5f * uniform(rng) - 0.25f, 0.5f * uniform(rng) - 0.25f}, {-1, 0.001f * uniform(rng), 0}};
    EXPECT_TRUE(same_answer(bvh.closest_hit(r, {}), bf.closest_hit(r, {})));
    RayStats st;
    EXPECT_TRUE(same_answer(bvh.closest_hit(r, {}, &st), bf.closest_hit(r, {})));
  }
}

// ---- Refit ----

TEST(BvhRefit, AnswersLikeAFreshBuildAfterVerticesMove) {
  auto tris = soup(4000, 12, 0.03f);
  Bvh bvh(tris, quiet());
  std::mt19937 rng(13);
  for (Triangle& t : tris) {
    const glm::vec3 shift = 0.2f * random_direction(rng);
    t = {t.v0 + shift, t.v1 + shift, t.v2 + 0.05f * random_direction(rng) + shift};
  }
  const auto before = std::vector<BvhNode>(bvh.nodes().begin(), bvh.nodes().end());
  bvh.refit(tris);
  // Topology unchanged, bounds tight around the moved triangles.
  ASSERT_EQ(bvh.nodes().size(), before.size());
  for (std::size_t i = 0; i < before.size(); ++i) {
    const BvhNode& n = bvh.nodes()[i];
    EXPECT_EQ(n.index, before[i].index);
    EXPECT_EQ(n.count, before[i].count);
    Aabb expect;
    if (n.count > 0)
      for (std::uint32_t k = n.index; k < n.index + n.count; ++k) expect.extend(tris[bvh.prim_indices()[k]].bounds());
    else
      expect = Aabb::merge(bvh.nodes()[n.index].bounds, bvh.nodes()[n.index + 1].bounds);
    EXPECT_TRUE(expect.lo == n.bounds.lo && expect.hi == n.bounds.hi) << "node " << i;
  }
  const Bvh fresh(tris, quiet());
  const BruteForce bf(tris);
  for (const Ray& r : rays_through_unit_cube(3000, 14)) {
    const Hit ref = bf.closest_hit(r, {});
    EXPECT_TRUE(same_answer(bvh.closest_hit(r, {}), ref));
    EXPECT_TRUE(same_answer(fresh.closest_hit(r, {}), ref));
    EXPECT_EQ(bvh.any_hit(r, {}), ref.valid());
  }
  // Moving every triangle independently loosens the old grouping.
  EXPECT_GT(bvh.build_stats().sah_cost, fresh.build_stats().sah_cost);
  EXPECT_GE(bvh.build_stats().extra.at("refit_ms"), 0.0);
}

TEST(BvhRefit, RefitToTheSamePositionsRestoresTheBuild) {
  const auto tris = soup(3000, 15);
  BvhOptions o;  // EPO on: refit recomputes it too
  Bvh bvh(tris, o);
  const std::vector<BvhNode> built(bvh.nodes().begin(), bvh.nodes().end());
  const double sah = bvh.build_stats().sah_cost;
  const double epo = bvh.build_stats().extra.at("epo");
  auto moved = tris;
  for (Triangle& t : moved) t.v0 *= 1.5f;
  bvh.refit(moved);
  EXPECT_NE(bvh.build_stats().sah_cost, sah);
  bvh.refit(tris);
  ASSERT_EQ(bvh.nodes().size(), built.size());
  EXPECT_EQ(std::memcmp(bvh.nodes().data(), built.data(), built.size() * sizeof(BvhNode)), 0);
  EXPECT_EQ(bvh.build_stats().sah_cost, sah);
  EXPECT_EQ(bvh.build_stats().extra.at("epo"), epo);
  // The wide copy follows the refit too: answers equal a fresh build's.
  const Bvh fresh(tris, o);
  for (const Ray& r : rays_through_unit_cube(2000, 17)) {
    const Hit a = bvh.closest_hit(r, {}), b = fresh.closest_hit(r, {});
    EXPECT_EQ(a.prim, b.prim);
    EXPECT_EQ(a.t, b.t);
  }
}

TEST(BvhRefit, RejectsADifferentTriangleCount) {
  const auto tris = soup(100, 16);
  Bvh bvh(tris, quiet());
  const std::vector<Triangle> fewer(tris.begin(), tris.begin() + 99);
  EXPECT_THROW(bvh.refit(fewer), std::invalid_argument);
}

TEST(BvhRefit, EmptyTreeRefitsToNothing) {
  const std::vector<Triangle> none;
  Bvh bvh(none, quiet());
  EXPECT_NO_THROW(bvh.refit(none));
  EXPECT_TRUE(bvh.nodes().empty());
}
}  // namespace unity_test_bvh_query
