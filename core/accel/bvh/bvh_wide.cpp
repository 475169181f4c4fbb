// Collapse of a binary BVH into 4-wide nodes (see bvh_wide.h).
#include "core/accel/bvh/bvh_wide.h"

#include "core/math/aabb.h"

namespace accelviz::bvh_detail {
namespace {

void set_slot(WideNode& w, int slot, const Aabb& b) {
  w.bounds[0][slot] = b.lo.x;
  w.bounds[1][slot] = b.lo.y;
  w.bounds[2][slot] = b.lo.z;
  w.bounds[3][slot] = b.hi.x;
  w.bounds[4][slot] = b.hi.y;
  w.bounds[5][slot] = b.hi.z;
}

WideNode empty_node() {
  WideNode w;
  for (int s = 0; s < 4; ++s) {
    set_slot(w, s, Aabb::empty());  // lo = +inf, hi = -inf: missed by every finite ray
    w.child[s] = 0;
    w.meta[s] = kWideEmpty;
  }
  return w;
}

}  // namespace

WideBvh collapse_to_wide(std::span<const BvhNode> binary) {
  WideBvh wide;
  if (binary.empty()) return wide;
  wide.nodes.reserve(binary.size() / 2 + 1);
  wide.source.reserve(2 * binary.size() + 4);

  // Work list of (wide node to fill, binary node whose children it takes).
  std::vector<std::pair<std::uint32_t, std::uint32_t>> work;
  wide.nodes.push_back(empty_node());
  wide.source.insert(wide.source.end(), 4, kWideEmpty);
  if (binary[0].count > 0) {
    // A single leaf: one slot.
    set_slot(wide.nodes[0], 0, binary[0].bounds);
    wide.nodes[0].child[0] = binary[0].index;
    wide.nodes[0].meta[0] = binary[0].count;
    wide.source[0] = 0;
    return wide;
  }
  work.push_back({0, 0});
  while (!work.empty()) {
    const auto [w, b] = work.back();
    work.pop_back();
    // 1. Gather up to four binary nodes under b: open the largest inner one.
    std::uint32_t slots[4] = {binary[b].index, binary[b].index + 1, 0, 0};
    int n = 2;
    while (n < 4) {
      int open = -1;
      float best = -1.0f;
      for (int s = 0; s < n; ++s) {
        const BvhNode& c = binary[slots[s]];
        if (c.count == 0 && c.bounds.surface_area() > best) {
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
      wide.source[4 * w + s] = slots[s];
      set_slot(wide.nodes[w], s, c.bounds);
      if (c.count > 0) {
        wide.nodes[w].child[s] = c.index;
        wide.nodes[w].meta[s] = c.count;
      } else {
        const auto child = static_cast<std::uint32_t>(wide.nodes.size());
        wide.nodes.push_back(empty_node());
        wide.source.insert(wide.source.end(), 4, kWideEmpty);
        wide.nodes[w].child[s] = child;
        wide.nodes[w].meta[s] = 0;
      }
    }
    // Depth first, first slot first (pushed last).
    for (int s = n - 1; s >= 0; --s)
      if (wide.nodes[w].meta[s] == 0) work.push_back({wide.nodes[w].child[s], slots[s]});
  }
  return wide;
}

void build_tri4_blocks(WideBvh& wide, std::span<const Triangle> leaf_tris) {
  wide.tri_blocks.clear();
  wide.tri_blocks.reserve(leaf_tris.size() / 2 + 1);
  for (WideNode& n : wide.nodes)
    for (int s = 0; s < 4; ++s)
      if (n.meta[s] != 0 && n.meta[s] != kWideEmpty)
        n.child[s] = append_tri4_blocks(leaf_tris, n.child[s], n.meta[s], wide.tri_blocks);
  wide.tri_blocks.shrink_to_fit();
}

void refit_wide(WideBvh& wide, std::span<const BvhNode> binary) {
  for (std::size_t w = 0; w < wide.nodes.size(); ++w)
    for (int s = 0; s < 4; ++s)
      if (wide.source[4 * w + s] != kWideEmpty) set_slot(wide.nodes[w], s, binary[wide.source[4 * w + s]].bounds);
}

int wide_slab_test_scalar(const WideNode& node, const Ray& ray, float tmin, float tmax, float t_entry[4],
                          float t_exit[4]) {
  int mask = 0;
  for (int s = 0; s < 4; ++s) {
    const Aabb box{{node.bounds[0][s], node.bounds[1][s], node.bounds[2][s]},
                   {node.bounds[3][s], node.bounds[4][s], node.bounds[5][s]}};
    SlabInterval iv;
    if (intersect_slab(box, ray.origin, ray.inv_dir, tmin, tmax, iv)) mask |= 1 << s;
    t_entry[s] = iv.t_entry;
    t_exit[s] = iv.t_exit;
  }
  return mask;
}

}  // namespace accelviz::bvh_detail
