// Binned SAH search: the SIMD bucket sweep (three axes in one register)
// gives the candidate costs the scalar formula gives, bit for bit, so the
// tree does not depend on which sweep ran.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
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
      const glm::vec3 a(u(rng), u(rng), u(rng)), b(u(rng), u(rng), u(rng));
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

}  // namespace accelviz::binned_sweep_test
