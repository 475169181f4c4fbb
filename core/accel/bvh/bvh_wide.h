#pragma once
// A 4- or 8-wide copy of a binary BVH, used only by the uninstrumented (fast)
// traversal: 8-wide with AVX2 and FMA where the CPU has them (checked at run time),
// else 4-wide with SSE.
//
// Why: single-ray traversal of a binary BVH is latency-bound. Every step
// loads a child pair, runs a slab test and takes a data-dependent branch;
// mispredicted branches cost the whole test latency. Collapsing the tree so
// that each node holds up to four children (Dammertz et al., "Shallow
// Bounding Volume Hierarchies for Fast SIMD Ray Tracing of Incoherent Rays",
// EGSR 2008; Wald et al. 2008; the layout Embree uses) halves the number of
// sequential steps and tests four (eight) boxes with one set of SIMD instructions.
//
// The binary node array stays the structure that is built, shown, counted
// and refitted: the statistics/trace path traverses it, and every wide slot
// records the binary node it copies, so a refit updates both. Leaves are the
// binary tree's leaves (the same primitive ranges).
#include <bit>
#include <cstdint>
#include <span>
#include <vector>

#include "core/accel/bvh/bvh.h"
#include "core/accel/bvh/bvh_tri4.h"
#include "core/util/huge_page_allocator.h"

namespace accelviz::bvh_detail {

/// W child boxes in structure-of-arrays order, then the children (W = 4:
/// 128 bytes, SSE; W = 8: 256 bytes, AVX2). meta = 0: inner wide node
/// `child`; 1..255: leaf of `meta` primitives starting at leaf position
/// `child` (after lay_out_leaf_blocks: `meta` triangle blocks starting
/// at block `child`); kWideEmpty: unused slot.
template <int W>
struct alignas(64) WideNodeT {
  float bounds[6][W];  ///< [lo.x, lo.y, lo.z, hi.x, hi.y, hi.z][slot]
  std::uint32_t child[W];
  std::uint32_t meta[W];
};
using WideNode = WideNodeT<4>;
using WideNode8 = WideNodeT<8>;

/// The ordered closest-hit walk's order of a wide node's hit slots (bits of
/// `mask`): nearest entry distance `te[slot]` first, equal distances in slot
/// order (-0 equal to +0), computed without branching on the distances: on
/// incoherent rays an insertion sort's compares are coin tosses, each a
/// mispredicted branch (the 8-wide walk's diffuse closest hits measured 3-6 %
/// faster without them, docs/performance.md).
///
/// Exactly two hit slots, the commonest case: one conditional move.
[[gnu::always_inline]] inline void order_two_hit_slots(int mask, const float* te, int& near, int& far) {
  const unsigned m = static_cast<unsigned>(mask);
  const int a = std::countr_zero(m), b = std::countr_zero(m & (m - 1));
  const bool swap = te[b] < te[a];
  near = swap ? b : a;
  far = swap ? a : b;
}

/// Three or more hit slots, into slot[0..k), nearest first; returns k. Keys
/// hold a distance's bits, made to order as unsigned integers, above its
/// slot: three or four go through a sorting network of min/max, more (8-wide
/// only) through an insertion sort of the keys.
template <int W>
[[gnu::always_inline]] inline int sort_hit_slots(int mask, const float* te, int* slot) {
  const unsigned m = static_cast<unsigned>(mask);
  std::uint64_t key[W];
  int k = 0;
  for (unsigned left = m; left != 0; left &= left - 1) {
    const int s = std::countr_zero(left);
    const auto bits = std::bit_cast<std::uint32_t>(te[s] + 0.0f);  // -0 + 0 = +0
    const std::uint32_t ordered =
        bits ^ (static_cast<std::uint32_t>(static_cast<std::int32_t>(bits) >> 31) | 0x80000000u);
    key[k++] = (static_cast<std::uint64_t>(ordered) << 32) | static_cast<std::uint32_t>(s);
  }
  const auto cas = [&key](int i, int j) {
    const std::uint64_t a = key[i], b = key[j];
    key[i] = a < b ? a : b;
    key[j] = a < b ? b : a;
  };
  if (k == 3) {
    cas(0, 1);
    cas(1, 2);
    cas(0, 1);
  } else if (k == 4) {
    cas(0, 1);
    cas(2, 3);
    cas(0, 2);
    cas(1, 3);
    cas(1, 2);
  } else {
    for (int i = 1; i < k; ++i) {
      const std::uint64_t v = key[i];
      int j = i;
      for (; j > 0 && key[j - 1] > v; --j) key[j] = key[j - 1];
      key[j] = v;
    }
  }
  for (int i = 0; i < k; ++i) slot[i] = static_cast<int>(key[i] & 0xFFFFFFFFu);
  return k;
}

static_assert(sizeof(WideNode) == 128);
static_assert(sizeof(WideNode8) == 256);

inline constexpr std::uint32_t kWideEmpty = 0xFFFFFFFFu;

template <int W>
struct WideBvhT {
  /// Root at 0; empty when the binary tree is. On huge pages where the
  /// system allows (huge_page_allocator.h): the walk reads it at random.
  HugePageVector<WideNodeT<W>> nodes;
  HugePageVector<std::uint32_t> source;  ///< W per wide node: the binary node each slot copies (kWideEmpty if unused)
};
struct WideBvh : WideBvhT<4> {};
struct WideBvh8 : WideBvhT<8> {};

/// Calls f(leaf) for every binary leaf under `node` (itself if a leaf), left
/// child first: the order of their primitive ranges.
template <class F>
void for_each_leaf_under(std::span<const BvhNode> binary, std::uint32_t node, const F& f) {
  if (binary[node].count > 0) {
    f(node);
    return;
  }
  for_each_leaf_under(binary, binary[node].index, f);
  for_each_leaf_under(binary, binary[node].index + 1, f);
}

/// One step of laying the triangle blocks out: binary leaf `leaf` takes the
/// leaf-order entry `order_entry`, its blocks from block `next` on
/// (leaf_block[leaf] = next). Returns the block after its last. Both
/// layouts place their leaves with it: class Bvh without a wide copy in node
/// order, lay_out_leaf_blocks per leaf slot.
inline std::uint32_t place_leaf_blocks(std::span<const BvhNode> binary, std::uint32_t leaf, std::uint32_t next,
                                       std::uint32_t& order_entry, std::span<std::uint32_t> leaf_block) {
  order_entry = leaf;
  leaf_block[leaf] = next;
  return next + tri4_block_count(binary[leaf].count);
}

/// Lays class Bvh's triangle blocks (bvh_tri4.h) out in the order of the
/// leaf slots and points every leaf slot at its blocks, in one walk: each
/// slot's binary leaves one after the other (for_each_leaf_under's order),
/// each binary leaf from a new block. Appends every binary leaf to
/// `leaf_order`, sets `leaf_block[binary leaf]` to its first block, and sets
/// the slot's child = its first block, meta = its block count (before, a
/// leaf slot names a leaf position and a primitive count, as collapse_to_wide
/// leaves it).
/// On `threads` threads (0: all); the result does not depend on them.
template <int W>
void lay_out_leaf_blocks(WideBvhT<W>& wide, std::span<const BvhNode> binary, HugePageVector<std::uint32_t>& leaf_order,
                         std::span<std::uint32_t> leaf_block, unsigned threads = 1);

/// Collapses a binary node array: each wide node takes a binary inner node's
/// children and keeps opening the child with the largest surface area until
/// it has W (or only leaves are left). Deterministic; wide children are
/// stored after their parent.
///
/// merge_blocks > 0: a binary inner node whose leaves fill at most that many
/// triangle blocks of four (each leaf from a new block) becomes one leaf slot
/// (its box, all its primitives, which are contiguous), as if the builder had
/// kept it as a leaf. The binary tree, which is built, shown and counted, is
/// unchanged; only the fast path's copy has fewer, larger leaves (see
/// docs/bvh.md: fewer wide nodes to fetch per ray).
///
/// On `threads` threads (0: all), below a frontier of subtrees; the array is
/// the same whatever the threads: the one a single depth-first pass makes.
template <int W>
void collapse_to_wide(std::span<const BvhNode> binary, WideBvhT<W>& wide, int merge_blocks = 0, unsigned threads = 1);
inline WideBvh collapse_to_wide(std::span<const BvhNode> binary) {
  WideBvh w;
  collapse_to_wide<4>(binary, w);
  return w;
}

/// Copies the binary boxes into the wide nodes again (after a refit).
template <int W>
void refit_wide(WideBvhT<W>& wide, std::span<const BvhNode> binary);

/// Scalar twin of the W-box test: core/math/aabb.h's robust slab test per
/// slot. Bit i of the result: slot i hit; t_entry[i]/t_exit[i] its interval.
template <int W>
int wide_slab_test_scalar(const WideNodeT<W>& node, const Ray& ray, float tmin, float tmax, float t_entry[W],
                          float t_exit[W]);

/// True when this CPU runs the 8-wide traversal (AVX2 and FMA; and this build has it).
bool cpu_has_wide8();

}  // namespace accelviz::bvh_detail
