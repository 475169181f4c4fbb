// Collapse of a binary BVH into 4- or 8-wide nodes (see bvh_wide.h).
#include "core/accel/bvh/bvh_wide.h"

#include "core/accel/bvh/bvh_slab.h"
#include "core/math/aabb.h"

namespace accelviz::bvh_detail {
namespace {

template <int W>
void set_slot(WideNodeT<W>& w, int slot, const Aabb& b) {
  w.bounds[0][slot] = b.lo.x;
  w.bounds[1][slot] = b.lo.y;
  w.bounds[2][slot] = b.lo.z;
  w.bounds[3][slot] = b.hi.x;
  w.bounds[4][slot] = b.hi.y;
  w.bounds[5][slot] = b.hi.z;
}

template <int W>
WideNodeT<W> empty_node() {
  WideNodeT<W> w;
  for (int s = 0; s < W; ++s) {
    set_slot(w, s, Aabb::empty());  // lo = +inf, hi = -inf: missed by every finite ray
    w.child[s] = 0;
    w.meta[s] = kWideEmpty;
  }
  return w;
}

/// Per binary node: the triangle blocks its leaves fill (each leaf from a
/// new block), its primitive count and its first leaf position. Children are
/// stored after their parents, so one reverse sweep fills them.
struct SubtreeBlocks {
  HugePageVector<std::uint32_t> blocks, count, first;
  explicit SubtreeBlocks(std::span<const BvhNode> binary)
      : blocks(binary.size()), count(binary.size()), first(binary.size()) {
    for (std::size_t i = binary.size(); i-- > 0;) {
      const BvhNode& n = binary[i];
      if (n.count > 0) {
        blocks[i] = tri4_block_count(n.count);
        count[i] = n.count;
        first[i] = n.index;
      } else {
        blocks[i] = blocks[n.index] + blocks[n.index + 1];
        count[i] = count[n.index] + count[n.index + 1];
        first[i] = first[n.index];
      }
    }
  }
};

}  // namespace

template <int W>
void collapse_to_wide(std::span<const BvhNode> binary, WideBvhT<W>& wide, int merge_blocks) {
  wide.nodes.clear();
  wide.source.clear();
  if (binary.empty()) return;
  const SubtreeBlocks sub(binary);
  // Binary nodes that become one leaf slot: the leaves, and with merging the
  // inner nodes over few enough blocks (a slot counts at most 255 primitives).
  HugePageVector<std::uint8_t> leaf_like(binary.size(), 0);
  for (std::size_t i = 0; i < binary.size(); ++i)
    leaf_like[i] =
        binary[i].count > 0 ||
        (merge_blocks > 0 && sub.blocks[i] <= static_cast<std::uint32_t>(merge_blocks) && sub.count[i] <= 255u);
  // Each wide node takes the children of one binary inner node: at most
  // binary.size() / 2 + 1 of them, W source entries each. Reserved pages that
  // are never written are never touched (HugePageVector), so the worst case
  // costs address space only.
  wide.nodes.reserve(binary.size() / 2 + 1);
  wide.source.reserve(static_cast<std::size_t>(W) * (binary.size() / 2 + 1));

  // Work list of (wide node to fill, binary node whose children it takes).
  std::vector<std::pair<std::uint32_t, std::uint32_t>> work;
  wide.nodes.push_back(empty_node<W>());
  wide.source.insert(wide.source.end(), W, kWideEmpty);
  if (leaf_like[0]) {
    // A single leaf: one slot.
    set_slot(wide.nodes[0], 0, binary[0].bounds);
    wide.nodes[0].child[0] = sub.first[0];
    wide.nodes[0].meta[0] = sub.count[0];
    wide.source[0] = 0;
    return;
  }
  work.push_back({0, 0});
  while (!work.empty()) {
    const auto [w, b] = work.back();
    work.pop_back();
    // 1. Gather up to W binary nodes under b: open the largest inner one.
    std::uint32_t slots[W] = {binary[b].index, binary[b].index + 1};
    int n = 2;
    while (n < W) {
      int open = -1;
      float best = -1.0f;
      for (int s = 0; s < n; ++s) {
        const BvhNode& c = binary[slots[s]];
        if (!leaf_like[slots[s]] && c.bounds.surface_area() > best) {
          best = c.bounds.surface_area();
          open = s;
        }
      }
      if (open < 0) break;  // only leaves left
      const std::uint32_t opened = slots[open];
      // Keep the children in place of their parent: spatial order survives.
      for (int s = n; s > open + 1; --s) slots[s] = slots[s - 1];
      slots[open] = binary[opened].index;
      slots[open + 1] = binary[opened].index + 1;
      ++n;
    }
    // 2. Fill the slots; inner slots get new wide nodes, allocated together.
    for (int s = 0; s < n; ++s) {
      const BvhNode& c = binary[slots[s]];
      wide.source[W * w + s] = slots[s];
      set_slot(wide.nodes[w], s, c.bounds);
      if (leaf_like[slots[s]]) {
        wide.nodes[w].child[s] = sub.first[slots[s]];
        wide.nodes[w].meta[s] = sub.count[slots[s]];
      } else {
        const auto child = static_cast<std::uint32_t>(wide.nodes.size());
        wide.nodes.push_back(empty_node<W>());
        wide.source.insert(wide.source.end(), W, kWideEmpty);
        wide.nodes[w].child[s] = child;
        wide.nodes[w].meta[s] = 0;
      }
    }
    // Depth first, first slot first (pushed last).
    for (int s = n - 1; s >= 0; --s)
      if (wide.nodes[w].meta[s] == 0) work.push_back({wide.nodes[w].child[s], slots[s]});
  }
  // The reserve above is sized for 2-wide and wider trees use a fraction of
  // it, but it is not trimmed: its untouched pages are never resident, and a
  // trimming copy (shrink_to_fit) cost a fresh page fault per page of the
  // nodes, about 4 % of a dragon build.
}

template <int W>
void lay_out_leaf_blocks(WideBvhT<W>& wide, std::span<const BvhNode> binary, HugePageVector<std::uint32_t>& leaf_order,
                         std::span<std::uint32_t> leaf_block) {
  std::uint32_t next = 0;
  for (std::size_t w = 0; w < wide.nodes.size(); ++w)
    for (int s = 0; s < W; ++s)
      if (wide.nodes[w].meta[s] != 0 && wide.nodes[w].meta[s] != kWideEmpty) {
        const std::uint32_t first = next;
        for_each_leaf_under(binary, wide.source[W * w + s], [&](std::uint32_t leaf) {
          next = append_leaf_blocks(binary, leaf, next, leaf_order, leaf_block);
        });
        wide.nodes[w].child[s] = first;
        wide.nodes[w].meta[s] = next - first;
      }
}

template <int W>
void refit_wide(WideBvhT<W>& wide, std::span<const BvhNode> binary) {
  for (std::size_t w = 0; w < wide.nodes.size(); ++w)
    for (int s = 0; s < W; ++s)
      if (wide.source[W * w + s] != kWideEmpty) set_slot(wide.nodes[w], s, binary[wide.source[W * w + s]].bounds);
}

template <int W>
int wide_slab_test_scalar(const WideNodeT<W>& node, const Ray& ray, float tmin, float tmax, float t_entry[W],
                          float t_exit[W]) {
  int mask = 0;
  for (int s = 0; s < W; ++s) {
    const Aabb box{{node.bounds[0][s], node.bounds[1][s], node.bounds[2][s]},
                   {node.bounds[3][s], node.bounds[4][s], node.bounds[5][s]}};
    SlabInterval iv;
    if (intersect_slab(box, ray.origin, ray.inv_dir, tmin, tmax, iv)) mask |= 1 << s;
    t_entry[s] = iv.t_entry;
    t_exit[s] = iv.t_exit;
  }
  return mask;
}

bool cpu_has_wide8() {
#if defined(ACCELVIZ_BVH_WIDE8_AVX2)
  return __builtin_cpu_supports("avx2") != 0 && __builtin_cpu_supports("fma") != 0;
#else
  return false;
#endif
}

template void collapse_to_wide<4>(std::span<const BvhNode>, WideBvhT<4>&, int);
template void collapse_to_wide<8>(std::span<const BvhNode>, WideBvhT<8>&, int);
template void lay_out_leaf_blocks<4>(WideBvhT<4>&, std::span<const BvhNode>, HugePageVector<std::uint32_t>&,
                                     std::span<std::uint32_t>);
template void lay_out_leaf_blocks<8>(WideBvhT<8>&, std::span<const BvhNode>, HugePageVector<std::uint32_t>&,
                                     std::span<std::uint32_t>);
template void refit_wide<4>(WideBvhT<4>&, std::span<const BvhNode>);
template void refit_wide<8>(WideBvhT<8>&, std::span<const BvhNode>);
template int wide_slab_test_scalar<4>(const WideNodeT<4>&, const Ray&, float, float, float*, float*);
template int wide_slab_test_scalar<8>(const WideNodeT<8>&, const Ray&, float, float, float*, float*);

}  // namespace accelviz::bvh_detail
