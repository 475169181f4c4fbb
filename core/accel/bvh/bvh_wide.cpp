// Collapse of a binary BVH into 4- or 8-wide nodes (see bvh_wide.h).
#include "core/accel/bvh/bvh_wide.h"

#include <algorithm>
#include <utility>
#include <vector>

#include "core/accel/bvh/bvh_slab.h"
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

/// The binary nodes under binary inner node `b` that become one wide node's
/// slots (the first n of `slots`): b's children, then the inner one with the
/// largest surface area opened until there are W or only leaf-like ones,
/// each opened node's children in its place (spatial order survives).
template <int W>
int gather_slots(std::span<const BvhNode> binary, std::span<const std::uint8_t> leaf_like, std::uint32_t b,
                 std::uint32_t (&slots)[W]) {
  // Each slot's surface area, computed once (-1 for a leaf-like slot, which
  // is never opened); the first of equal largest areas is opened.
  float area[W];
  const auto area_of = [&](std::uint32_t i) { return leaf_like[i] ? -1.0f : binary[i].bounds.surface_area(); };
  slots[0] = binary[b].index;
  slots[1] = binary[b].index + 1;
  area[0] = area_of(slots[0]);
  area[1] = area_of(slots[1]);
  int n = 2;
  while (n < W) {
    int open = -1;
    float best = -1.0f;
    for (int s = 0; s < n; ++s)
      if (area[s] > best) {
        best = area[s];
        open = s;
      }
    if (open < 0) break;  // only leaves left
    const std::uint32_t opened = slots[open];
    for (int s = n; s > open + 1; --s) {
      slots[s] = slots[s - 1];
      area[s] = area[s - 1];
    }
    slots[open] = binary[opened].index;
    slots[open + 1] = binary[opened].index + 1;
    area[open] = area_of(slots[open]);
    area[open + 1] = area_of(slots[open + 1]);
    ++n;
  }
  return n;
}

/// One wide node from the `n` gathered `slots`: their boxes and binary
/// sources (the other slots empty); a leaf-like slot names its first leaf
/// position and primitive count, the k-th inner slot the wide node
/// `inner_child(k, slot)` returns.
template <int W, class InnerChild>
void write_slots(std::span<const BvhNode> binary, std::span<const std::uint8_t> leaf_like, const SubtreeBlocks& sub,
                 const std::uint32_t (&slots)[W], int n, WideNodeT<W>& node, std::uint32_t* source,
                 InnerChild&& inner_child) {
  node = empty_node<W>();
  std::fill(source, source + W, kWideEmpty);
  int k = 0;
  for (int s = 0; s < n; ++s) {
    source[s] = slots[s];
    set_slot(node, s, binary[slots[s]].bounds);
    if (leaf_like[slots[s]]) {
      node.child[s] = sub.first[slots[s]];
      node.meta[s] = sub.count[slots[s]];
    } else {
      node.child[s] = inner_child(k++, slots[s]);
      node.meta[s] = 0;
    }
  }
}

/// The collapse in two passes over the binary tree, each on all threads
/// below a frontier of subtrees, giving exactly the array a single
/// depth-first pass gives: that pass puts a wide node's children together at
/// the array's end when it takes the node, then takes the first child's
/// subtree, then the second's. So with S(b) the wide nodes below the one
/// made from binary node b, the children of a node taken at position P go to
/// P, P+1, ..., and child i's own children to P + k + S(c_1) + ... +
/// S(c_{i-1}) (k inner children): pass 1 counts S bottom-up, pass 2 writes
/// every node at its place top-down.
template <int W>
class Collapse {
 public:
  Collapse(std::span<const BvhNode> binary, std::span<const std::uint8_t> leaf_like, const SubtreeBlocks& sub,
           WideBvhT<W>& wide, unsigned threads)
      : binary_(binary), leaf_like_(leaf_like), sub_(sub), wide_(wide), threads_(threads), below_(binary.size()) {
    // Subtrees of at most this many primitives are one task each.
    grain_ = std::max<std::uint32_t>(4096, sub.count[0] / (16 * std::max(1u, threads)));
  }

  void run() {
    // Pass 1: S for every wide node, the frontier's subtrees on all threads.
    std::vector<std::uint32_t> frontier;
    collect_frontier(0, frontier);
    parallel_for(frontier.size(), threads_, 1, [&](std::size_t i0, std::size_t i1, unsigned) {
      for (std::size_t i = i0; i < i1; ++i) count(frontier[i], false);
    });
    const std::uint32_t total = 1 + count(0, true);
    wide_.nodes.resize(total);  // default-initialised: every node is written below
    wide_.source.resize(static_cast<std::size_t>(W) * total);
    // Pass 2: every node at its place; the frontier's subtrees on all threads.
    std::vector<Task> tasks;
    fill(Task{0, 0, 1}, &tasks);
    parallel_for(tasks.size(), threads_, 1, [&](std::size_t i0, std::size_t i1, unsigned) {
      for (std::size_t i = i0; i < i1; ++i) fill(tasks[i], nullptr);
    });
  }

 private:
  struct Task {
    std::uint32_t wide;      ///< the wide node to write
    std::uint32_t binary;    ///< the binary inner node whose children it takes
    std::uint32_t children;  ///< where its inner children go (P)
  };

  bool frontier(std::uint32_t b) const { return sub_.count[b] <= grain_; }

  void collect_frontier(std::uint32_t b, std::vector<std::uint32_t>& out) const {
    if (frontier(b)) {
      out.push_back(b);
      return;
    }
    std::uint32_t slots[W];
    const int n = gather_slots<W>(binary_, leaf_like_, b, slots);
    for (int s = 0; s < n; ++s)
      if (!leaf_like_[slots[s]]) collect_frontier(slots[s], out);
  }

  /// S(b), stored in below_[b] for b and every wide node under it; `above`:
  /// b lies above the frontier, whose counts are done.
  std::uint32_t count(std::uint32_t b, bool above) {
    if (above && frontier(b)) return below_[b];
    std::uint32_t slots[W];
    const int n = gather_slots<W>(binary_, leaf_like_, b, slots);
    std::uint32_t sum = 0;
    for (int s = 0; s < n; ++s)
      if (!leaf_like_[slots[s]]) sum += 1 + count(slots[s], above);
    below_[b] = sum;
    return sum;
  }

  /// Writes wide node t.wide and its subtree; with `defer`, a child on the
  /// frontier is left as a task instead.
  void fill(const Task& t, std::vector<Task>* defer) {
    std::uint32_t slots[W];
    const int n = gather_slots<W>(binary_, leaf_like_, t.binary, slots);
    int inner = 0;
    for (int s = 0; s < n; ++s) inner += leaf_like_[slots[s]] ? 0 : 1;
    Task next[W];
    int k = 0;
    std::uint32_t grand = t.children + static_cast<std::uint32_t>(inner);  // the first child's children
    write_slots<W>(binary_, leaf_like_, sub_, slots, n, wide_.nodes[t.wide],
                   wide_.source.data() + static_cast<std::size_t>(W) * t.wide, [&](int i, std::uint32_t b) {
                     next[i] = Task{t.children + static_cast<std::uint32_t>(i), b, grand};
                     grand += below_[b];
                     k = i + 1;
                     return next[i].wide;
                   });
    for (int i = 0; i < k; ++i) {
      if (defer && frontier(next[i].binary))
        defer->push_back(next[i]);
      else
        fill(next[i], defer);
    }
  }

  std::span<const BvhNode> binary_;
  std::span<const std::uint8_t> leaf_like_;
  const SubtreeBlocks& sub_;
  WideBvhT<W>& wide_;
  unsigned threads_;
  std::uint32_t grain_ = 0;
  HugePageVector<std::uint32_t> below_;  ///< S per binary node that becomes a wide node
};

/// The single depth-first pass itself, for one thread (the two passes of
/// Collapse cost it a third more there): each wide node's children are put
/// together at the array's end when the node is taken.
template <int W>
void collapse_serial(std::span<const BvhNode> binary, std::span<const std::uint8_t> leaf_like, const SubtreeBlocks& sub,
                     WideBvhT<W>& wide) {
  // At most binary.size() / 2 + 1 wide nodes: reserved pages that are never
  // written are never touched (HugePageVector), so this costs address space.
  wide.nodes.reserve(binary.size() / 2 + 1);
  wide.source.reserve(static_cast<std::size_t>(W) * (binary.size() / 2 + 1));
  wide.nodes.resize(1);  // the root, written when taken
  wide.source.resize(W);
  std::vector<std::pair<std::uint32_t, std::uint32_t>> work{{0, 0}};  // (wide node, binary node)
  while (!work.empty()) {
    const auto [w, b] = work.back();
    work.pop_back();
    std::uint32_t slots[W];
    const int n = gather_slots<W>(binary, leaf_like, b, slots);
    // The children's places first (the arrays grow), then the node itself.
    std::uint32_t children[W];
    int inner = 0;
    for (int s = 0; s < n; ++s)
      if (!leaf_like[slots[s]]) {
        children[inner] = static_cast<std::uint32_t>(wide.nodes.size()) + static_cast<std::uint32_t>(inner);
        ++inner;
      }
    wide.nodes.resize(wide.nodes.size() + inner);
    wide.source.resize(wide.source.size() + static_cast<std::size_t>(W) * inner);
    write_slots<W>(binary, leaf_like, sub, slots, n, wide.nodes[w],
                   wide.source.data() + static_cast<std::size_t>(W) * w,
                   [&](int i, std::uint32_t) { return children[i]; });
    // Depth first, first slot first (pushed last).
    for (int s = n - 1; s >= 0; --s)
      if (wide.nodes[w].meta[s] == 0) work.push_back({wide.nodes[w].child[s], slots[s]});
  }
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
  HugePageVector<std::uint8_t> leaf_like(binary.size());
  parallel_for(binary.size(), threads, 16384, [&](std::size_t i0, std::size_t i1, unsigned) {
    for (std::size_t i = i0; i < i1; ++i)
      leaf_like[i] =
          binary[i].count > 0 ||
          (merge_blocks > 0 && sub.blocks[i] <= static_cast<std::uint32_t>(merge_blocks) && sub.count[i] <= 255u);
  });
  if (leaf_like[0]) {
    // A single leaf: one slot.
    wide.nodes.push_back(empty_node<W>());
    wide.source.insert(wide.source.end(), W, kWideEmpty);
    set_slot(wide.nodes[0], 0, binary[0].bounds);
    wide.nodes[0].child[0] = sub.first[0];
    wide.nodes[0].meta[0] = sub.count[0];
    wide.source[0] = 0;
    return;
  }
  if (resolve_threads(threads) == 1)
    collapse_serial<W>(binary, leaf_like, sub, wide);
  else
    Collapse<W>(binary, leaf_like, sub, wide, resolve_threads(threads)).run();
}

template <int W>
void lay_out_leaf_blocks(WideBvhT<W>& wide, std::span<const BvhNode> binary, HugePageVector<std::uint32_t>& leaf_order,
                         std::span<std::uint32_t> leaf_block, unsigned threads) {
  // A single pass in node order puts each leaf slot's binary leaves next,
  // from block `next` and leaf position `at` on. On more threads, each node's
  // blocks and leaves are counted first and their running sums give each
  // node its `next` and `at`. Every binary leaf lies under one leaf slot, and
  // a binary tree of n nodes has (n + 1) / 2 leaves.
  const std::size_t count = wide.nodes.size();
  const auto is_leaf_slot = [&](std::size_t w, int s) {
    return wide.nodes[w].meta[s] != 0 && wide.nodes[w].meta[s] != kWideEmpty;
  };
  const std::size_t base = leaf_order.size();
  leaf_order.resize(base + (binary.size() + 1) / 2);  // default-initialised: every entry is written below
  const auto place = [&](std::size_t w, std::uint32_t next, std::size_t at) {
    for (int s = 0; s < W; ++s)
      if (is_leaf_slot(w, s)) {
        const std::uint32_t first = next;
        for_each_leaf_under(binary, wide.source[W * w + s], [&](std::uint32_t leaf) {
          next = place_leaf_blocks(binary, leaf, next, leaf_order[at++], leaf_block);
        });
        wide.nodes[w].child[s] = first;
        wide.nodes[w].meta[s] = next - first;
      }
    return std::pair{next, at};
  };
  threads = resolve_threads(threads);
  if (threads == 1) {
    std::pair<std::uint32_t, std::size_t> from{0, base};
    for (std::size_t w = 0; w < count; ++w) from = place(w, from.first, from.second);
    return;
  }
  std::vector<std::uint32_t> first_block(count + 1), first_leaf(count + 1);
  parallel_for(count, threads, 1024, [&](std::size_t w0, std::size_t w1, unsigned) {
    for (std::size_t w = w0; w < w1; ++w) {
      std::uint32_t blocks = 0, leaves = 0;
      for (int s = 0; s < W; ++s)
        if (is_leaf_slot(w, s))
          for_each_leaf_under(binary, wide.source[W * w + s], [&](std::uint32_t leaf) {
            blocks += tri4_block_count(binary[leaf].count);
            ++leaves;
          });
      first_block[w + 1] = blocks;
      first_leaf[w + 1] = leaves;
    }
  });
  for (std::size_t w = 0; w < count; ++w) {
    first_block[w + 1] += first_block[w];
    first_leaf[w + 1] += first_leaf[w];
  }
  parallel_for(count, threads, 1024, [&](std::size_t w0, std::size_t w1, unsigned) {
    for (std::size_t w = w0; w < w1; ++w) place(w, first_block[w], base + first_leaf[w]);
  });
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

template void collapse_to_wide<4>(std::span<const BvhNode>, WideBvhT<4>&, int, unsigned);
template void collapse_to_wide<8>(std::span<const BvhNode>, WideBvhT<8>&, int, unsigned);
template void lay_out_leaf_blocks<4>(WideBvhT<4>&, std::span<const BvhNode>, HugePageVector<std::uint32_t>&,
                                     std::span<std::uint32_t>, unsigned);
template void lay_out_leaf_blocks<8>(WideBvhT<8>&, std::span<const BvhNode>, HugePageVector<std::uint32_t>&,
                                     std::span<std::uint32_t>, unsigned);
template void refit_wide<4>(WideBvhT<4>&, std::span<const BvhNode>);
template void refit_wide<8>(WideBvhT<8>&, std::span<const BvhNode>);
template int wide_slab_test_scalar<4>(const WideNodeT<4>&, const Ray&, float, float, float*, float*);
template int wide_slab_test_scalar<8>(const WideNodeT<8>&, const Ray&, float, float, float*, float*);

}  // namespace accelviz::bvh_detail
