// The wide fast path's merged leaf slots (collapse_to_wide's merge_blocks) and
// the huge-page allocator of its arrays.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <stdexcept>
#include <vector>

#include "core/accel/brute_force.h"
#include "core/accel/bvh/bvh.h"
#include "core/accel/bvh/bvh_wide.h"
#include "core/util/huge_page_allocator.h"

// Own namespace: this file is compiled together with others (unity build).
namespace unity_test_bvh_wide_merge {

using namespace accelviz;

float merge_uniform(std::mt19937& rng) {
  return static_cast<float>(rng() >> 8) * (1.0f / 16777216.0f);
}

std::vector<Triangle> merge_soup(std::size_t n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<Triangle> tris(n);
  for (Triangle& t : tris) {
    const glm::vec3 c{merge_uniform(rng), merge_uniform(rng), merge_uniform(rng)};
    const auto jitter = [&] {
      return glm::vec3{merge_uniform(rng), merge_uniform(rng), merge_uniform(rng)} * 0.06f - 0.03f;
    };
    t = {c + jitter(), c + jitter(), c + jitter()};
  }
  return tris;
}

TEST(BvhWideMerge, MergedSlotsCoverEveryLeafOnceWithTheirSubtreeBox) {
  const auto tris = merge_soup(3000, 41);
  BvhOptions o;
  o.compute_epo = false;
  const Bvh bvh(tris, o);
  const auto nodes = bvh.nodes();
  bvh_detail::WideBvh8 plain, merged;
  bvh_detail::collapse_to_wide(nodes, plain);
  bvh_detail::collapse_to_wide(nodes, merged, 2);
  std::vector<int> leaf_seen(nodes.size(), 0);
  int merged_slots = 0;
  for (std::size_t w = 0; w < merged.nodes.size(); ++w)
    for (int s = 0; s < 8; ++s) {
      const bvh_detail::WideNode8& n = merged.nodes[w];
      if (n.meta[s] == bvh_detail::kWideEmpty || n.meta[s] == 0) continue;
      const std::uint32_t src = merged.source[8 * w + s];
      ASSERT_LT(src, nodes.size());
      EXPECT_EQ(n.bounds[0][s], nodes[src].bounds.lo.x);
      EXPECT_EQ(n.bounds[5][s], nodes[src].bounds.hi.z);
      // The slot's primitives: its binary leaves' ranges, one after the other.
      std::uint32_t count = 0, blocks = 0, next = n.child[s];
      bvh_detail::for_each_leaf_under(nodes, src, [&](std::uint32_t leaf) {
        ++leaf_seen[leaf];
        EXPECT_EQ(nodes[leaf].index, next);
        next = nodes[leaf].index + nodes[leaf].count;
        count += nodes[leaf].count;
        blocks += (nodes[leaf].count + 3) / 4;
      });
      EXPECT_EQ(n.meta[s], count);
      EXPECT_LE(count, 255u);
      if (nodes[src].count == 0) {
        ++merged_slots;
        EXPECT_LE(blocks, 2u);
      }
    }
  for (std::size_t i = 0; i < nodes.size(); ++i) EXPECT_EQ(leaf_seen[i], nodes[i].count > 0 ? 1 : 0) << i;
  EXPECT_GT(merged_slots, 0);
  EXPECT_LT(merged.nodes.size(), plain.nodes.size());
}

TEST(BvhWideMerge, MergingTreeAnswersLikeBruteForce) {
  // Class Bvh walks merged slots (blocks of several binary leaves, padding
  // lanes between them): the same hits as brute force, every width and test.
  const auto tris = merge_soup(1500, 42);
  const BruteForce bf(tris);
  std::mt19937 rng(43);
  for (int width : {4, 8}) {
    BvhOptions o;
    o.compute_epo = false;
    o.wide_width = width;
    o.wide_merge_blocks = 2;  // this small tree would not merge by default (auto: 16 MiB of blocks)
    const Bvh bvh(tris, o);
    EXPECT_EQ(bvh.build_stats().extra.at("wide_merge_blocks"), 2.0);
    for (int i = 0; i < 3000; ++i) {
      const glm::vec3 a{merge_uniform(rng), merge_uniform(rng), merge_uniform(rng)};
      const glm::vec3 b{merge_uniform(rng), merge_uniform(rng), merge_uniform(rng)};
      if (glm::length(b - a) < 1e-3f) continue;
      const Ray ray(a * 1.4f - 0.2f, glm::normalize(b - a));
      for (TriangleTest test : {TriangleTest::watertight, TriangleTest::moller_trumbore}) {
        QueryOptions q;
        q.triangle_test = test;
        const Hit h = bvh.closest_hit(ray, q), r = bf.closest_hit(ray, q);
        ASSERT_EQ(h.valid(), r.valid()) << width << " ray " << i;
        if (r.valid()) {
          EXPECT_EQ(h.t, r.t) << width << " ray " << i;
        }
        ASSERT_EQ(bvh.any_hit(ray, q), r.valid()) << width << " ray " << i;
      }
    }
  }
}

TEST(BvhWideMerge, AutoMergesOnlyLargeTreesAndTheOptionIsChecked) {
  const auto tris = merge_soup(2000, 44);
  BvhOptions o;
  o.compute_epo = false;
  o.wide_width = 8;
  const Bvh automatic(tris, o);  // 2000 triangles: far below 16 MiB of blocks
  EXPECT_EQ(automatic.build_stats().extra.at("wide_merge_blocks"), 0.0);
  o.wide_merge_blocks = 2;
  const Bvh merged(tris, o);
  EXPECT_LT(merged.build_stats().extra.at("wide_nodes"), automatic.build_stats().extra.at("wide_nodes"));
  EXPECT_EQ(merged.build_stats().extra.at("memory_tri_blocks"), automatic.build_stats().extra.at("memory_tri_blocks"));
  for (int bad : {-2, 64}) {
    o.wide_merge_blocks = bad;
    EXPECT_THROW(Bvh(tris, o), std::invalid_argument) << bad;
  }
}

TEST(HugePageAllocator, LargeArraysSitOnHugePageBoundariesSmallOnesAreOrdinary) {
  HugePageVector<std::uint32_t> big(kHugePageBytes / sizeof(std::uint32_t) + 7);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(big.data()) % kHugePageBytes, 0u);
  for (std::size_t i = 0; i < big.size(); ++i) big[i] = static_cast<std::uint32_t>(i);
  HugePageVector<std::uint32_t> copy = big;  // copies through the allocator too
  EXPECT_EQ(copy.back(), static_cast<std::uint32_t>(big.size() - 1));
  HugePageVector<std::uint32_t> small(10, 3u);
  small.push_back(4u);
  EXPECT_EQ(small.size(), 11u);
  EXPECT_EQ(small.back(), 4u);
  big.clear();
  big.shrink_to_fit();
  EXPECT_TRUE(big.empty());
}

TEST(HugePageAllocator, FreedLargeArraysAreReusedForArraysOfAboutTheirSize) {
  huge_page_detail::release_kept_regions();
  const std::size_t n = 2 * kHugePageBytes / sizeof(float);  // two huge pages
  const float* first = nullptr;
  {
    HugePageVector<float> a(n, 1.0f);
    first = a.data();
  }
  EXPECT_EQ(huge_page_detail::kept_bytes(), 2 * kHugePageBytes);
  {
    HugePageVector<float> b(n - 5);  // the same two pages: the kept region
    EXPECT_EQ(b.data(), first);
    EXPECT_EQ(huge_page_detail::kept_bytes(), 0u);
    HugePageVector<float> c(5 * n);  // more than the kept region: fresh memory
    EXPECT_NE(c.data(), first);
  }
  EXPECT_EQ(huge_page_detail::kept_bytes(), 12 * kHugePageBytes);  // b's two pages and c's ten
  {
    // One page: b's two pages are at most twice that, c's ten are not.
    HugePageVector<float> d(n / 2);
    EXPECT_EQ(d.data(), first);
    EXPECT_EQ(huge_page_detail::kept_bytes(), 10 * kHugePageBytes);
    HugePageVector<float> e(n / 2);  // nothing near one page is left: fresh memory
    EXPECT_EQ(huge_page_detail::kept_bytes(), 10 * kHugePageBytes);
    EXPECT_NE(e.data(), first);
  }
  huge_page_detail::release_kept_regions();
  EXPECT_EQ(huge_page_detail::kept_bytes(), 0u);
}

TEST(HugePageAllocator, AReusedRegionIsKeptAtItsTrueSize) {
  huge_page_detail::release_kept_regions();
  const std::size_t page_floats = kHugePageBytes / sizeof(float);
  const float* first = nullptr;
  { first = HugePageVector<float>(4 * page_floats).data(); }
  EXPECT_EQ(huge_page_detail::kept_bytes(), 4 * kHugePageBytes);
  {
    // Three pages' request: the kept four-page region (at most twice that).
    HugePageVector<float> a(3 * page_floats);
    EXPECT_EQ(a.data(), first);
    EXPECT_EQ(huge_page_detail::kept_bytes(), 0u);
  }
  // Freed again, it counts its four pages, not the request's three.
  EXPECT_EQ(huge_page_detail::kept_bytes(), 4 * kHugePageBytes);
  {
    // So a four-page request can take it again.
    HugePageVector<float> b(4 * page_floats);
    EXPECT_EQ(b.data(), first);
  }
  EXPECT_EQ(huge_page_detail::kept_bytes(), 4 * kHugePageBytes);
  huge_page_detail::release_kept_regions();
  EXPECT_EQ(huge_page_detail::kept_bytes(), 0u);
}

TEST(HugePageAllocator, KeptRegionsAreBoundedInCountAndBytes) {
  huge_page_detail::release_kept_regions();
  using huge_page_detail::KeptRegions;
  {
    std::vector<HugePageVector<char>> arrays;
    for (int i = 0; i < KeptRegions::kSlots + 4; ++i) arrays.emplace_back(kHugePageBytes);
  }
  // Only the newest kSlots regions are kept; the oldest were freed.
  EXPECT_EQ(huge_page_detail::kept_bytes(), KeptRegions::kSlots * kHugePageBytes);
  // A region larger than kKeptRegionBytes is freed at once, and the others stay.
  huge_page_detail::keep_region(std::malloc(16), KeptRegions::kKeptRegionBytes + kHugePageBytes);
  EXPECT_EQ(huge_page_detail::kept_bytes(), KeptRegions::kSlots * kHugePageBytes);
  huge_page_detail::release_kept_regions();
  EXPECT_EQ(huge_page_detail::kept_bytes(), 0u);
  // The largest kept regions, more than the byte budget holds (never touched:
  // address space only): the newest that fit are kept.
  const std::size_t fit = KeptRegions::kKeptBytes / KeptRegions::kKeptRegionBytes;
  {
    std::vector<HugePageVector<char>> arrays;
    for (std::size_t i = 0; i < fit + 2; ++i) arrays.emplace_back(KeptRegions::kKeptRegionBytes);
  }
  EXPECT_EQ(huge_page_detail::kept_bytes(), fit * KeptRegions::kKeptRegionBytes);
  EXPECT_LE(huge_page_detail::kept_bytes(), KeptRegions::kKeptBytes);
  huge_page_detail::release_kept_regions();
  EXPECT_EQ(huge_page_detail::kept_bytes(), 0u);
}

}  // namespace unity_test_bvh_wide_merge
