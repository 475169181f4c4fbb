// The wide tree's collapse and leaf-block layout on several threads
// (collapse_to_wide, lay_out_leaf_blocks): the same arrays, bit for bit, as a
// single depth-first pass (written out here as the reference: the algorithm
// the parallel one must reproduce) and as one thread.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <random>
#include <utility>
#include <vector>

#include "core/accel/bvh/bvh.h"
#include "core/accel/bvh/bvh_wide.h"
#include "core/scene/load.h"

// Own namespace: this file is compiled together with others (unity build).
namespace unity_test_bvh_wide_parallel {

using namespace accelviz;
using bvh_detail::kWideEmpty;

/// The reference: one depth-first pass with a work list, each wide node's
/// children put together at the array's end when the node is taken.
template <int W>
void reference_collapse(std::span<const BvhNode> binary, bvh_detail::WideBvhT<W>& wide, int merge_blocks) {
  const std::size_t n = binary.size();
  std::vector<std::uint32_t> blocks(n), count(n), first(n);
  for (std::size_t i = n; i-- > 0;) {
    const BvhNode& b = binary[i];
    if (b.count > 0) {
      blocks[i] = bvh_detail::tri4_block_count(b.count);
      count[i] = b.count;
      first[i] = b.index;
    } else {
      blocks[i] = blocks[b.index] + blocks[b.index + 1];
      count[i] = count[b.index] + count[b.index + 1];
      first[i] = first[b.index];
    }
  }
  std::vector<std::uint8_t> leaf_like(n);
  for (std::size_t i = 0; i < n; ++i)
    leaf_like[i] = binary[i].count > 0 ||
                   (merge_blocks > 0 && blocks[i] <= static_cast<std::uint32_t>(merge_blocks) && count[i] <= 255u);
  const auto empty = [] {
    bvh_detail::WideNodeT<W> w;
    for (int s = 0; s < W; ++s) {
      for (int a = 0; a < 3; ++a) w.bounds[a][s] = Aabb::empty().lo[a];
      for (int a = 0; a < 3; ++a) w.bounds[3 + a][s] = Aabb::empty().hi[a];
      w.child[s] = 0;
      w.meta[s] = kWideEmpty;
    }
    return w;
  };
  const auto set = [](bvh_detail::WideNodeT<W>& w, int s, const Aabb& b) {
    for (int a = 0; a < 3; ++a) w.bounds[a][s] = b.lo[a];
    for (int a = 0; a < 3; ++a) w.bounds[3 + a][s] = b.hi[a];
  };
  wide.nodes.clear();
  wide.source.clear();
  wide.nodes.push_back(empty());
  wide.source.insert(wide.source.end(), W, kWideEmpty);
  std::vector<std::pair<std::uint32_t, std::uint32_t>> work{{0, 0}};
  while (!work.empty()) {
    const auto [w, b] = work.back();
    work.pop_back();
    std::uint32_t slots[W] = {binary[b].index, binary[b].index + 1};
    int k = 2;
    while (k < W) {
      int open = -1;
      float best = -1.0f;
      for (int s = 0; s < k; ++s)
        if (!leaf_like[slots[s]] && binary[slots[s]].bounds.surface_area() > best) {
          best = binary[slots[s]].bounds.surface_area();
          open = s;
        }
      if (open < 0) break;
      const std::uint32_t opened = slots[open];
      for (int s = k; s > open + 1; --s) slots[s] = slots[s - 1];
      slots[open] = binary[opened].index;
      slots[open + 1] = binary[opened].index + 1;
      ++k;
    }
    for (int s = 0; s < k; ++s) {
      wide.source[W * w + s] = slots[s];
      set(wide.nodes[w], s, binary[slots[s]].bounds);
      if (leaf_like[slots[s]]) {
        wide.nodes[w].child[s] = first[slots[s]];
        wide.nodes[w].meta[s] = count[slots[s]];
      } else {
        const auto child = static_cast<std::uint32_t>(wide.nodes.size());
        wide.nodes.push_back(empty());
        wide.source.insert(wide.source.end(), W, kWideEmpty);
        wide.nodes[w].child[s] = child;
        wide.nodes[w].meta[s] = 0;
      }
    }
    for (int s = k - 1; s >= 0; --s)
      if (wide.nodes[w].meta[s] == 0) work.push_back({wide.nodes[w].child[s], slots[s]});
  }
}

/// The reference layout: the wide nodes in order, each leaf slot's binary
/// leaves one after the other.
template <int W>
void reference_layout(bvh_detail::WideBvhT<W>& wide, std::span<const BvhNode> binary,
                      std::vector<std::uint32_t>& leaf_order, std::vector<std::uint32_t>& leaf_block) {
  std::uint32_t next = 0;
  for (std::size_t w = 0; w < wide.nodes.size(); ++w)
    for (int s = 0; s < W; ++s)
      if (wide.nodes[w].meta[s] != 0 && wide.nodes[w].meta[s] != kWideEmpty) {
        const std::uint32_t first = next;
        bvh_detail::for_each_leaf_under(binary, wide.source[W * w + s], [&](std::uint32_t leaf) {
          leaf_order.push_back(leaf);
          leaf_block[leaf] = next;
          next += bvh_detail::tri4_block_count(binary[leaf].count);
        });
        wide.nodes[w].child[s] = first;
        wide.nodes[w].meta[s] = next - first;
      }
}

template <int W>
void expect_same(const bvh_detail::WideBvhT<W>& a, const bvh_detail::WideBvhT<W>& b, const std::string& what) {
  ASSERT_EQ(a.nodes.size(), b.nodes.size()) << what;
  ASSERT_EQ(a.source.size(), b.source.size()) << what;
  EXPECT_EQ(std::memcmp(a.nodes.data(), b.nodes.data(), a.nodes.size() * sizeof(a.nodes[0])), 0) << what;
  EXPECT_TRUE(std::equal(a.source.begin(), a.source.end(), b.source.begin())) << what;
}

template <int W>
void check_scene(std::span<const Triangle> tris, const std::string& name) {
  BvhOptions o;
  o.compute_epo = false;
  o.wide_traversal = false;
  const Bvh bvh(tris, o);
  const auto nodes = bvh.nodes();
  for (int merge : {0, 2}) {
    bvh_detail::WideBvhT<W> ref;
    reference_collapse<W>(nodes, ref, merge);
    std::vector<std::uint32_t> ref_order, ref_block(nodes.size(), 0);
    reference_layout<W>(ref, nodes, ref_order, ref_block);
    for (unsigned threads : {1u, 2u, 3u, 8u, 0u}) {  // 0: all hardware threads
      const std::string what =
          name + " W=" + std::to_string(W) + " merge=" + std::to_string(merge) + " threads=" + std::to_string(threads);
      bvh_detail::WideBvhT<W> wide;
      bvh_detail::collapse_to_wide<W>(nodes, wide, merge, threads);
      HugePageVector<std::uint32_t> order;
      std::vector<std::uint32_t> block(nodes.size(), 0);
      bvh_detail::lay_out_leaf_blocks<W>(wide, nodes, order, block, threads);
      expect_same(wide, ref, what);
      EXPECT_TRUE(std::equal(order.begin(), order.end(), ref_order.begin(), ref_order.end())) << what;
      EXPECT_EQ(block, ref_block) << what;
    }
  }
}

std::vector<Triangle> soup(std::size_t n, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f), j(-0.02f, 0.02f);
  std::vector<Triangle> tris(n);
  for (Triangle& t : tris) {
    const glm::vec3 c{u(rng), u(rng), u(rng)};
    t = {c + glm::vec3{j(rng), j(rng), j(rng)}, c + glm::vec3{j(rng), j(rng), j(rng)},
         c + glm::vec3{j(rng), j(rng), j(rng)}};
  }
  return tris;
}

TEST(BvhWideParallel, CollapseAndLayoutOnThreadsEqualOneDepthFirstPass) {
  // Large enough that the parallel collapse has a frontier of many subtrees
  // (its grain is at least 4096 primitives), small enough to stay quick.
  const std::vector<Triangle> s = soup(120000, 7);
  check_scene<8>(s, "soup");
  check_scene<4>(s, "soup");
  const Scene teapot = load_scene("builtin:teapot?size=60000");
  check_scene<8>(teapot.triangles, "teapot");
  const Scene tiny = load_scene("builtin:teapot-stadium?size=3000");
  check_scene<8>(tiny.triangles, "teapot-stadium");
}

TEST(BvhWideParallel, ASingleLeafAndAnEmptyTreeStayAsTheyWere) {
  const std::vector<Triangle> one = soup(3, 1);
  BvhOptions o;
  o.compute_epo = false;
  const Bvh bvh(one, o);
  ASSERT_EQ(bvh.nodes().size(), 1u);
  bvh_detail::WideBvh8 wide;
  bvh_detail::collapse_to_wide<8>(bvh.nodes(), wide, 0, 4);
  ASSERT_EQ(wide.nodes.size(), 1u);
  EXPECT_EQ(wide.nodes[0].meta[0], 3u);
  EXPECT_EQ(wide.nodes[0].meta[1], kWideEmpty);
  EXPECT_EQ(wide.source[0], 0u);
  bvh_detail::collapse_to_wide<8>({}, wide, 0, 4);
  EXPECT_TRUE(wide.nodes.empty());
}

}  // namespace unity_test_bvh_wide_parallel
