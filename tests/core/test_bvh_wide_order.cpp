// The ordered closest-hit walk's child order on the wide BVH (bvh_wide.h:
// order_two_hit_slots, sort_hit_slots): nearest entry distance first, equal
// distances in slot order, -0 equal to +0, exactly as a stable sort by
// distance would give, for every hit count of 4- and 8-wide nodes.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <limits>
#include <random>
#include <vector>

#include "core/accel/bvh/bvh_wide.h"

// Own namespace: this file is compiled together with others (unity build).
namespace unity_test_bvh_wide_order {

using namespace accelviz;
using bvh_detail::order_two_hit_slots;
using bvh_detail::sort_hit_slots;

/// The reference: the hit slots in slot order, stably sorted by distance
/// (float comparison: -0 == +0).
std::vector<int> stable_order(int mask, const float* te) {
  std::vector<int> s;
  for (int i = 0; i < 32; ++i)
    if ((mask >> i) & 1) s.push_back(i);
  std::stable_sort(s.begin(), s.end(), [te](int a, int b) { return te[a] < te[b]; });
  return s;
}

/// The walk's order: two hit slots through order_two_hit_slots, more through
/// sort_hit_slots<W>.
template <int W>
std::vector<int> walk_order(int mask, const float* te) {
  if (std::popcount(static_cast<unsigned>(mask)) == 2) {
    int near = -1, far = -1;
    order_two_hit_slots(mask, te, near, far);
    return {near, far};
  }
  int slot[W];
  const int k = sort_hit_slots<W>(mask, te, slot);
  return std::vector<int>(slot, slot + k);
}

template <int W>
void check_random_nodes(std::uint32_t seed) {
  std::mt19937 rng(seed);
  // Few distinct distances, so that ties are common; both zeros; negative
  // entries (a ray whose tmin is negative keeps the exact box test) and
  // large, tiny and subnormal ones.
  const float pool[] = {0.0f,  -0.0f, 1.0f,   1.0f,   2.5f,    -3.0f,   -0.5f,       1e-30f,
                        1e30f, 7.25f, 0.125f, 1e-40f, -1e-40f, 3.0e38f, 1.0f + 1e-7f};
  std::uniform_int_distribution<int> pick(0, static_cast<int>(std::size(pool)) - 1);
  std::uniform_real_distribution<float> any(-100.0f, 100.0f);
  int checked[W + 1] = {};
  for (int i = 0; i < 200000; ++i) {
    const int mask = static_cast<int>(rng() & ((1u << W) - 1));
    if (std::popcount(static_cast<unsigned>(mask)) < 2) continue;
    alignas(32) float te[W];
    for (float& t : te) t = rng() % 3 == 0 ? any(rng) : pool[pick(rng)];
    const std::vector<int> got = walk_order<W>(mask, te), want = stable_order(mask, te);
    ASSERT_EQ(got, want) << W << "-wide, mask " << mask << ", node " << i;
    ++checked[std::popcount(static_cast<unsigned>(mask))];
  }
  for (int k = 2; k <= W; ++k) EXPECT_GT(checked[k], 100) << k << " hit slots";
}

TEST(BvhWideOrder, HitSlotsNearestFirstTiesInSlotOrderAsAStableSort) {
  check_random_nodes<4>(5);
  check_random_nodes<8>(6);
}

TEST(BvhWideOrder, BothZerosAreOneDistanceAndTheLowerSlotGoesFirst) {
  alignas(32) float te[8] = {0.0f, -0.0f, 1.0f, -0.0f, 0.0f, 2.0f, 0.0f, -0.0f};
  int near = -1, far = -1;
  order_two_hit_slots(0b11, te, near, far);  // +0 in slot 0, -0 in slot 1
  EXPECT_EQ(near, 0);
  EXPECT_EQ(far, 1);
  te[0] = -0.0f;
  te[1] = 0.0f;
  order_two_hit_slots(0b11, te, near, far);
  EXPECT_EQ(near, 0);
  EXPECT_EQ(far, 1);
  int slot[8];
  ASSERT_EQ(sort_hit_slots<8>(0b11011011, te, slot), 6);
  EXPECT_EQ(std::vector<int>(slot, slot + 6), (std::vector<int>{0, 1, 3, 4, 6, 7}));
  ASSERT_EQ(sort_hit_slots<4>(0b1110, te, slot), 3);
  EXPECT_EQ(std::vector<int>(slot, slot + 3), (std::vector<int>{1, 3, 2}));
}

TEST(BvhWideOrder, TheFarthestOfEightAndTheNearestLastAreMoved) {
  alignas(32) float te[8] = {8, 7, 6, 5, 4, 3, 2, 1};
  int slot[8];
  ASSERT_EQ(sort_hit_slots<8>(0xFF, te, slot), 8);
  EXPECT_EQ(std::vector<int>(slot, slot + 8), (std::vector<int>{7, 6, 5, 4, 3, 2, 1, 0}));
  const float inf = std::numeric_limits<float>::infinity();
  alignas(32) float te4[4] = {inf, 1.0f, inf, 0.5f};
  ASSERT_EQ(sort_hit_slots<4>(0b1101, te4, slot), 3);
  EXPECT_EQ(std::vector<int>(slot, slot + 3), (std::vector<int>{3, 0, 2}));
}

}  // namespace unity_test_bvh_wide_order
