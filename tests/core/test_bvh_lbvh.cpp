// The LBVH builder (core/accel/bvh/lbvh_builder.cpp): Morton codes, the
// radix sort, the highest-differing-bit split, and its quality next to SAH.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "core/accel/bvh/bvh.h"
#include "core/accel/bvh/bvh_build.h"
#include "core/scene/load.h"
#include "tests/core/mt_random.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_bvh_lbvh {

using namespace accelviz;
using namespace accelviz::bvh_detail;

namespace {

using test_random::uniform;

std::vector<BuildPrim> random_prims(std::size_t n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<BuildPrim> p(n);
  for (std::size_t i = 0; i < n; ++i) {
    const glm::vec3 c{uniform(rng), uniform(rng), uniform(rng)};
    p[i] = BuildPrim{c, static_cast<std::uint32_t>(i), Aabb{c - 0.01f, c + 0.01f}};
  }
  return p;
}

}  // namespace

TEST(BvhLbvh, MortonCodesInterleaveXyzBits) {
  Aabb unit;
  unit.extend(glm::vec3(0.0f));
  unit.extend(glm::vec3(1.0f));
  const MortonFrame f = morton_frame(unit);
  EXPECT_EQ(morton_code({0, 0, 0}, f), 0u);
  // Cell 1023 on every axis: all 30 bits set.
  EXPECT_EQ(morton_code({1, 1, 1}, f), 0x3FFFFFFFu);
  // The top cell bit of x alone is the code's highest bit (x leads).
  EXPECT_EQ(morton_code({0.5f, 0, 0}, f), 1u << 29);
  EXPECT_EQ(morton_code({0, 0.5f, 0}, f), 1u << 28);
  EXPECT_EQ(morton_code({0, 0, 0.5f}, f), 1u << 27);
  // Below the box, NaN and above it clamp to the end cells.
  EXPECT_EQ(morton_code({-5, std::nanf(""), 0}, f), 0u);
  EXPECT_EQ(morton_code({7, 7, 7}, f), 0x3FFFFFFFu);
}

TEST(BvhLbvh, RadixSortOrdersByCodeThenIdOnAnyThreadCount) {
  auto prims = random_prims(200000, 3);
  // Many equal codes: a coarse frame over a larger box.
  Aabb box;
  box.extend(glm::vec3(0.0f));
  box.extend(glm::vec3(64.0f));
  const MortonFrame f = morton_frame(box);
  auto ref = prims;
  std::stable_sort(ref.begin(), ref.end(), [&](const BuildPrim& a, const BuildPrim& b) {
    return morton_code(a.centroid, f) < morton_code(b.centroid, f);
  });
  for (unsigned threads : {1u, 2u, 3u}) {
    auto p = prims;
    lbvh_sort(p, f, threads);
    ASSERT_EQ(p.size(), ref.size());
    for (std::size_t i = 0; i < p.size(); ++i) ASSERT_EQ(p[i].id, ref[i].id) << "threads " << threads << " at " << i;
  }
}

TEST(BvhLbvh, SplitCutsAtTheHighestDifferingBit) {
  auto prims = random_prims(5000, 5);
  Aabb b, c;
  range_bounds(prims, b, c);
  SplitParams params;
  params.morton = morton_frame(c);
  lbvh_sort(prims, params.morton, 1);
  SplitScratch scratch;
  SplitResult out;
  ASSERT_EQ(split_lbvh(params, prims, b, c, scratch, out), SplitOutcome::split);
  // Uniform points: the top bit (x's highest) splits near the middle; left
  // codes have it clear, right codes set.
  for (std::size_t i = 0; i < prims.size(); ++i)
    ASSERT_EQ((morton_code(prims[i].centroid, params.morton) >> 29) & 1u, i < out.mid ? 0u : 1u) << i;
  EXPECT_GT(out.mid, 2000u);
  EXPECT_LT(out.mid, 3000u);
  // With the sort's codes kept (as the build does) the cut is the same, on
  // the whole range and on a sub-range.
  SplitParams with_codes = params;
  const auto codes = lbvh_sort(prims, params.morton, 1);  // already sorted: the same order
  with_codes.morton_codes = codes;
  with_codes.morton_base = prims.data();
  SplitResult kept;
  ASSERT_EQ(split_lbvh(with_codes, prims, b, c, scratch, kept), SplitOutcome::split);
  EXPECT_EQ(kept.mid, out.mid);
  const std::span<BuildPrim> left = std::span<BuildPrim>(prims).first(out.mid);
  SplitResult sub, sub_kept;
  ASSERT_EQ(split_lbvh(params, left, b, c, scratch, sub), SplitOutcome::split);
  ASSERT_EQ(split_lbvh(with_codes, left, b, c, scratch, sub_kept), SplitOutcome::split);
  EXPECT_EQ(sub_kept.mid, sub.mid);
  // All codes equal: nothing to cut.
  std::vector<BuildPrim> same(10, prims[0]);
  EXPECT_EQ(split_lbvh(params, same, b, c, scratch, out), SplitOutcome::unsplittable);
}

TEST(BvhLbvh, QualityIsBelowBinnedSahButBounded) {
  // SAH cost of the LBVH next to binned SAH on a real-ish mesh: worse (no
  // cost model) but the same order of magnitude.
  const Scene s = make_builtin("builtin:teapot?size=20000");
  BvhOptions o;
  o.compute_epo = false;
  const Bvh sah(s.triangles, o);
  o.splitter = BvhSplitter::lbvh;
  const Bvh lbvh(s.triangles, o);
  EXPECT_GT(lbvh.build_stats().sah_cost, sah.build_stats().sah_cost);
  EXPECT_LT(lbvh.build_stats().sah_cost, 2.0 * sah.build_stats().sah_cost);
}
}  // namespace unity_test_bvh_lbvh
