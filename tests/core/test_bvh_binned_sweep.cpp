// Binned SAH search: the SIMD bucket sweep (three axes in one register)
// gives the candidate costs the scalar formula gives, bit for bit, so the
// tree does not depend on which sweep ran.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "core/accel/bvh/bvh_build.h"

namespace accelviz::binned_sweep_test {

TEST(BvhBinnedSweep, CandidateCostsEqualTheScalarFormulaBitForBit) {
  std::mt19937 rng(41);
  std::uniform_real_distribution<float> u(-3.0f, 7.0f);
  for (int round = 0; round < 40; ++round) {
    const int buckets = 2 + static_cast<int>(rng() % 255);
    const std::size_t n = 5 + rng() % 300;
    std::vector<bvh_detail::BuildPrim> prims(n);
    Aabb cb;
    for (std::uint32_t i = 0; i < n; ++i) {
      const glm::vec3 a{u(rng), u(rng), u(rng)}, b{u(rng), u(rng), u(rng)};
      prims[i] = {(a + b) * 0.5f, i, Aabb{glm::min(a, b), glm::max(a, b)}};
      if (round % 5 == 0) prims[i].centroid.z = 1.0f;  // a flat axis: unusable
      cb.extend(prims[i].centroid);
    }
    bvh_detail::Bins bins;
    bvh_detail::BinnedSahSearch s;
    bvh_detail::CandidateCosts costs;
    ASSERT_TRUE(bvh_detail::binned_sah_search(buckets, prims, cb, bins, s, &costs));
    int compared = 0;
    for (int a = 0; a < 3; ++a) {
      std::uint32_t total = 0;
      for (int b = 0; b < buckets; ++b) total += bins.count[a][b];
      ASSERT_EQ(total, n);
      for (int b = 0; b + 1 < buckets; ++b) {
        Aabb left, right;
        std::uint32_t nl = 0, nr = 0;
        for (int c = 0; c <= b; ++c) left.extend(bvh_detail::bucket_box(bins, a, c)), nl += bins.count[a][c];
        for (int c = buckets - 1; c > b; --c) right.extend(bvh_detail::bucket_box(bins, a, c)), nr += bins.count[a][c];
        if (!s.usable[a] || nl == 0 || nr == 0) {
          EXPECT_TRUE(std::isnan(costs[a][b])) << a << " " << b;
          continue;
        }
        const float expect = left.half_area() * static_cast<float>(nl) + right.half_area() * static_cast<float>(nr);
        ASSERT_EQ(costs[a][b], expect) << "round " << round << " axis " << a << " plane " << b;
        ++compared;
      }
    }
    EXPECT_GT(compared, 0);
    // The chosen plane is the cheapest candidate.
    ASSERT_GE(s.best_axis, 0);
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b + 1 < buckets; ++b)
        if (!std::isnan(costs[a][b])) {
          EXPECT_LE(s.best_cost, costs[a][b]);
        }
  }
}

// The search without recorded costs picks its plane with SIMD compares
// (min cost, then the smallest imbalance, then the first in axis/plane
// order); the recording search runs the sequential better_split loop. Both
// must choose the same plane, ties included (many equal boxes make equal costs).
TEST(BvhBinnedSweep, BranchFreeSelectionPicksTheSequentialLoopsPlane) {
  std::mt19937 rng(43);
  std::uniform_real_distribution<float> u(-3.0f, 7.0f);
  int ties = 0;
  for (int round = 0; round < 200; ++round) {
    const int buckets = 2 + static_cast<int>(rng() % (round % 3 == 0 ? 255 : 31));
    const std::size_t n = 2 + rng() % 200;
    std::vector<bvh_detail::BuildPrim> prims(n);
    Aabb cb;
    const int distinct = 1 + static_cast<int>(rng() % 6);  // few distinct boxes: equal costs
    std::vector<glm::vec3> lo(distinct), hi(distinct);
    for (int d = 0; d < distinct; ++d) {
      const glm::vec3 a{u(rng), u(rng), u(rng)}, b{u(rng), u(rng), u(rng)};
      lo[d] = glm::min(a, b);
      hi[d] = glm::max(a, b);
    }
    for (std::uint32_t i = 0; i < n; ++i) {
      const int d = round % 2 == 0 ? static_cast<int>(rng() % distinct) : -1;
      const glm::vec3 a = d >= 0 ? lo[d] : glm::vec3{u(rng), u(rng), u(rng)};
      const glm::vec3 b = d >= 0 ? hi[d] : glm::vec3{u(rng), u(rng), u(rng)};
      prims[i] = {(a + b) * 0.5f, i, Aabb{glm::min(a, b), glm::max(a, b)}};
      if (round % 7 == 0) prims[i].centroid.y = 2.0f;  // a flat axis: unusable
      cb.extend(prims[i].centroid);
    }
    bvh_detail::Bins bins_a, bins_b;
    bvh_detail::BinnedSahSearch fast, seq;
    bvh_detail::CandidateCosts costs;
    const bool ok_fast = bvh_detail::binned_sah_search(buckets, prims, cb, bins_a, fast);
    const bool ok_seq = bvh_detail::binned_sah_search(buckets, prims, cb, bins_b, seq, &costs);
    ASSERT_EQ(ok_fast, ok_seq) << round;
    if (!ok_fast) continue;
    ASSERT_EQ(fast.best_axis, seq.best_axis) << "round " << round;
    ASSERT_EQ(fast.best_bucket, seq.best_bucket) << "round " << round;
    ASSERT_EQ(fast.best_left, seq.best_left) << "round " << round;
    if (seq.best_axis >= 0) {
      ASSERT_EQ(fast.best_cost, seq.best_cost) << "round " << round;
      int equal = 0;
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b + 1 < buckets; ++b) equal += costs[a][b] == seq.best_cost ? 1 : 0;
      ties += equal > 1 ? 1 : 0;
    }
  }
  EXPECT_GT(ties, 10);  // the tie-break was exercised
}

// The partition's branch-free test agrees with bucket_of on every plane,
// including values below the origin, beyond the top bucket, NaN and inf.
TEST(BvhBinnedSweep, LeftOfPlaneMatchesBucketOf) {
  std::mt19937 rng(44);
  std::uniform_real_distribution<float> u(-2.0f, 12.0f);
  const float specials[] = {std::numeric_limits<float>::quiet_NaN(),
                            std::numeric_limits<float>::infinity(),
                            -std::numeric_limits<float>::infinity(),
                            -0.0f,
                            0.0f,
                            1e30f,
                            -1e30f};
  for (int round = 0; round < 300; ++round) {
    const int buckets = 2 + static_cast<int>(rng() % 255);
    const float lo = u(rng), k = static_cast<float>(buckets) / (0.5f + std::abs(u(rng)));
    for (int i = 0; i < 64; ++i) {
      float c = lo + u(rng) * (static_cast<float>(buckets) / k) * 0.1f;
      if (i < 7) c = specials[i];
      if (i == 7) c = lo + static_cast<float>(rng() % static_cast<unsigned>(buckets)) / k;  // on a bucket edge
      const int bucket = bvh_detail::bucket_of(c, lo, k, buckets);
      for (int plane = 0; plane + 1 < buckets; ++plane)
        ASSERT_EQ(bvh_detail::left_of_plane(c, lo, k, plane), bucket <= plane)
            << "c " << c << " lo " << lo << " k " << k << " plane " << plane;
    }
  }
}

}  // namespace accelviz::binned_sweep_test
