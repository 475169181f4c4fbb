// Collapse of a binary BVH into 4- or 8-wide nodes (see bvh_wide.h).
#include "core/accel/bvh/bvh_wide.h"

#include "core/accel/bvh/bvh_slab.h"
#include <algorithm>
#include <vector>

#include "core/math/aabb.h"
#include "core/util/parallel.h"

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


/// One step of the collapse: fills wide node `w` of `nodes`/`source` with the
/// slots gathered under binary inner node `b` and appends an empty wide node
/// for each inner slot; returns the (wide node, binary node) pairs still to
/// fill, in slot order.
template <int W>
int fill_wide_node(std::span<const BvhNode> binary, const SubtreeBlocks& sub,
                   std::span<const std::uint8_t> leaf_like, HugePageVector<WideNodeT<W>>& nodes,
                   HugePageVector<std::uint32_t>& source, std::uint32_t w, std::uint32_t b,
                   std::pair<std::uint32_t, std::uint32_t> (&pending)[W]) {
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
  int count = 0;
  for (int s = 0; s < n; ++s) {
    const BvhNode& c = binary[slots[s]];
    source[W * w + s] = slots[s];
    set_slot(nodes[w], s, c.bounds);
    if (leaf_like[slots[s]]) {
      nodes[w].child[s] = sub.first[slots[s]];
      nodes[w].meta[s] = sub.count[slots[s]];
    } else {
      const auto child = static_cast<std::uint32_t>(nodes.size());
      nodes.push_back(empty_node<W>());
      source.insert(source.end(), W, kWideEmpty);
      nodes[w].child[s] = child;
      nodes[w].meta[s] = 0;
      pending[count++] = {child, slots[s]};
    }
  }
  return count;
}

}  // namespace

template <int W>
void collapse_to_wide(std::span<const BvhNode> binary, WideBvhT<W>& wide, int merge_blocks, unsigned threads) {
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
  wide.nodes.reserve(binary.size() / 2 + 1);
  wide.source.reserve(2 * binary.size() + 4);

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
  using Item = std::pair<std::uint32_t, std::uint32_t>;  // (wide node to fill, binary node whose children it takes)
  // 1. The top, breadth first, until enough subtrees are pending.
  std::vector<Item> queue{{0, 0}};
  std::size_t head = 0;
  while (head < queue.size() && queue.size() - head < kWideCollapseParts) {
    const Item it = queue[head++];
    Item pending[W];
    const int k = fill_wide_node<W>(binary, sub, leaf_like, wide.nodes, wide.source, it.first, it.second, pending);
    queue.insert(queue.end(), pending, pending + k);
  }
  const std::span<const Item> parts(queue.data() + head, queue.size() - head);
  if (parts.empty()) return;

  // 2. Each pending subtree depth first into its own arrays, whose node 0
  //    stands for the subtree's (already allocated) root.
  struct Part {
    HugePageVector<WideNodeT<W>> nodes;
    HugePageVector<std::uint32_t> source;
  };
  std::vector<Part> out(parts.size());
  parallel_for(parts.size(), threads, 1, [&](std::size_t begin, std::size_t end, unsigned) {
    std::vector<Item> work;
    Item pending_here[W];
    for (std::size_t p = begin; p < end; ++p) {
      Part& part = out[p];
      part.nodes.reserve(sub.count[parts[p].second] / 4 + 1);
      part.source.reserve(W * (sub.count[parts[p].second] / 4 + 1));
      part.nodes.push_back(empty_node<W>());
      part.source.insert(part.source.end(), W, kWideEmpty);
      work.assign(1, Item{0, parts[p].second});
      while (!work.empty()) {
        const Item it = work.back();
        work.pop_back();
        const int k =
            fill_wide_node<W>(binary, sub, leaf_like, part.nodes, part.source, it.first, it.second, pending_here);
        for (int i = k - 1; i >= 0; --i) work.push_back(pending_here[i]);  // first slot first (pushed last)
      }
    }
  });

  // 3. Splice the parts after the top, in order: a part's node 0 replaces its
  //    root's placeholder, local node i >= 1 goes to base + i - 1.
  std::vector<std::size_t> base(parts.size());
  std::size_t total = wide.nodes.size();
  for (std::size_t p = 0; p < parts.size(); ++p) {
    base[p] = total;
    total += out[p].nodes.size() - 1;
  }
  wide.nodes.resize(total);
  wide.source.resize(W * total);
  parallel_for(parts.size(), threads, 1, [&](std::size_t begin, std::size_t end, unsigned) {
    for (std::size_t p = begin; p < end; ++p) {
      const Part& part = out[p];
      const auto rebase = [&](WideNodeT<W> node) {
        for (int s = 0; s < W; ++s)
          if (node.meta[s] == 0) node.child[s] = static_cast<std::uint32_t>(base[p] + node.child[s] - 1);
        return node;
      };
      const std::uint32_t root = parts[p].first;
      wide.nodes[root] = rebase(part.nodes[0]);
      std::copy_n(part.source.begin(), W, wide.source.begin() + W * root);
      for (std::size_t i = 1; i < part.nodes.size(); ++i) wide.nodes[base[p] + i - 1] = rebase(part.nodes[i]);
      std::copy(part.source.begin() + W, part.source.end(), wide.source.begin() + W * base[p]);
    }
  });
}

template <int W>
std::uint32_t lay_out_leaf_blocks(WideBvhT<W>& wide, std::span<const BvhNode> binary,
                                  HugePageVector<std::uint32_t>& leaf_order, std::span<std::uint32_t> leaf_block) {
  std::uint32_t next = 0;
  for (std::size_t w = 0; w < wide.nodes.size(); ++w)
    for (int s = 0; s < W; ++s)
      if (wide.nodes[w].meta[s] != 0 && wide.nodes[w].meta[s] != kWideEmpty) {
        const std::uint32_t first = next;
        for_each_leaf_under(binary, wide.source[W * w + s], [&](std::uint32_t leaf) {
          leaf_order.push_back(leaf);
          leaf_block[leaf] = next;
          next += tri4_block_count(binary[leaf].count);
        });
        wide.nodes[w].child[s] = first;
        wide.nodes[w].meta[s] = next - first;
      }
  return next;
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
  return __builtin_cpu_supports("avx2") != 0;
#else
  return false;
#endif
}

template void collapse_to_wide<4>(std::span<const BvhNode>, WideBvhT<4>&, int, unsigned);
template void collapse_to_wide<8>(std::span<const BvhNode>, WideBvhT<8>&, int, unsigned);
template std::uint32_t lay_out_leaf_blocks<4>(WideBvhT<4>&, std::span<const BvhNode>, HugePageVector<std::uint32_t>&,
                                              std::span<std::uint32_t>);
template std::uint32_t lay_out_leaf_blocks<8>(WideBvhT<8>&, std::span<const BvhNode>, HugePageVector<std::uint32_t>&,
                                              std::span<std::uint32_t>);
template void refit_wide<4>(WideBvhT<4>&, std::span<const BvhNode>);
template void refit_wide<8>(WideBvhT<8>&, std::span<const BvhNode>);
template int wide_slab_test_scalar<4>(const WideNodeT<4>&, const Ray&, float, float, float*, float*);
template int wide_slab_test_scalar<8>(const WideNodeT<8>&, const Ray&, float, float, float*, float*);

}  // namespace accelviz::bvh_detail
