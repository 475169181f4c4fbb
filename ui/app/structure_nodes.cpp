#include "ui/app/structure_nodes.h"

#include <algorithm>
#include <limits>

#include "core/accel/bvh/bvh.h"
#include "core/accel/grid/grid.h"
#include "core/accel/kdtree/kdtree.h"
#include "core/accel/octree/octree.h"
#include "core/accel/tlas/tlas.h"
#include "core/accel/voxels/voxels.h"
#include "core/util/one_line.h"

namespace accelviz {
namespace {

constexpr std::uint32_t kNone = 0xFFFFFFFFu;

// Tables are filled by an explicit stack (no recursion): K-D trees and
// degenerate BVHs can be 64 deep, and a corrupt array must not blow the stack.
struct Pending {
  std::uint32_t id;
  Aabb box;
  std::uint32_t depth;
  std::uint32_t parent;
};

/// Binary node i's children (first, first + 1) get i as their parent and its
/// depth + 1. Children come after their parent, so one forward sweep over a
/// BVH's array sets every depth; ids out of order or range are skipped.
void link_children(std::vector<StructureNode>& out, std::uint32_t i, std::uint32_t first, std::size_t count) {
  for (std::uint32_t c : {first, first + 1})
    if (c > i && c < count) {
      out[c].parent = i;
      out[c].depth = out[i].depth + 1;
    }
}

/// Fills `out` (`count` nodes) for a tree whose node boxes follow from the
/// root's (K-D tree, octree): from node 0 with box `root`, each node's box,
/// depth and parent set, then expand(p, node, push) sets its leaf figures or
/// calls push(child, child_box) for its children. A child whose id is not
/// larger than its parent's is not pushed (so a corrupt array cannot loop),
/// nor is one out of range.
template <class Expand>
void fill_from_root(std::vector<StructureNode>& out, std::size_t count, const Aabb& root, const Expand& expand) {
  out.resize(count);
  std::vector<Pending> stack;
  if (count > 0) stack.push_back({0, root, 0, kNone});
  while (!stack.empty()) {
    const Pending p = stack.back();
    stack.pop_back();
    StructureNode& n = out[p.id];
    n.bounds = p.box;
    n.depth = p.depth;
    n.parent = p.parent;
    expand(p, n, [&](std::uint32_t child, const Aabb& box) {
      if (child > p.id && child < count) stack.push_back({child, box, p.depth + 1, p.id});
    });
  }
}

}  // namespace

StructureNodes StructureNodes::of(const Accelerator& accel) {
  StructureNodes t;
  if (const auto* bvh = dynamic_cast<const Bvh*>(&accel)) {
    t.kind_ = "bvh";
    const auto nodes = bvh->nodes();
    t.nodes_.resize(nodes.size());
    // Children come after their parent, so one forward sweep sets depths.
    for (std::uint32_t i = 0; i < nodes.size(); ++i) {
      StructureNode& n = t.nodes_[i];
      n.bounds = nodes[i].bounds;
      n.leaf = nodes[i].is_leaf();
      n.prims = n.leaf ? nodes[i].count : 0;
      if (!n.leaf) link_children(t.nodes_, i, nodes[i].index, nodes.size());
    }
    t.finish(bvh->options().cost_traversal, bvh->options().cost_intersect);
  } else if (const auto* tlas = dynamic_cast<const Tlas*>(&accel)) {
    // TLAS nodes as a BVH, then one leaf per instance (its world box, the
    // BLAS triangle count) under the TLAS leaf that holds it: the boxes view
    // shows the top level, "leaves" shows the instances.
    t.kind_ = "tlas";
    const auto nodes = tlas->tlas_nodes();
    const auto order = tlas->tlas_instance_order();
    const auto instances = tlas->instances();
    t.nodes_.resize(nodes.size());
    for (std::uint32_t i = 0; i < nodes.size(); ++i) {
      StructureNode& n = t.nodes_[i];
      n.bounds = nodes[i].bounds;
      if (!nodes[i].is_leaf()) {
        link_children(t.nodes_, i, nodes[i].index, nodes.size());
        continue;
      }
      for (std::uint32_t k = nodes[i].index; k < nodes[i].index + nodes[i].count && k < order.size(); ++k) {
        const TlasInstance& inst = instances[order[k]];
        StructureNode leaf;
        leaf.bounds = inst.world_bounds;
        leaf.parent = i;
        leaf.depth = t.nodes_[i].depth + 1;
        leaf.leaf = true;
        leaf.prims = static_cast<std::uint32_t>(tlas->blas(inst.blas).triangle_count());
        leaf.instance = order[k];
        t.nodes_.push_back(leaf);
      }
    }
    t.finish(1.0f, 1.0f);
  } else if (const auto* kd = dynamic_cast<const KdTree*>(&accel)) {
    t.kind_ = "kdtree";
    const auto nodes = kd->nodes();
    fill_from_root(t.nodes_, nodes.size(), kd->bounds(), [&](const Pending& p, StructureNode& n, const auto& push) {
      const KdNode& k = nodes[p.id];
      n.leaf = k.is_leaf();
      if (n.leaf) {
        n.prims = k.prim_count();
        return;
      }
      Aabb below = p.box, above = p.box;
      below.hi[k.axis()] = k.split();
      above.lo[k.axis()] = k.split();
      push(k.above_child(), above);
      push(p.id + 1, below);
    });
    t.finish(kd->options().cost_traversal, kd->options().cost_intersect);
  } else if (const auto* oct = dynamic_cast<const Octree*>(&accel)) {
    t.kind_ = "octree";
    const auto nodes = oct->nodes();
    fill_from_root(t.nodes_, nodes.size(), oct->root_box(), [&](const Pending& p, StructureNode& n, const auto& push) {
      n.leaf = nodes[p.id].is_leaf();
      if (n.leaf) {
        n.prims = nodes[p.id].count;
        return;
      }
      for (int o = 7; o >= 0; --o) {
        push(nodes[p.id].index + static_cast<std::uint32_t>(o), Octree::child_box(p.box, o));
      }
    });
    t.finish(1.0f, 1.0f);  // the octree's SAH figure uses unit costs too
  } else if (const auto* vox = dynamic_cast<const Voxels*>(&accel)) {
    t.kind_ = "voxels";
    const auto nodes = vox->nodes();
    const VoxelDomain& dom = vox->domain();
    // Interior nodes keep their ids (what the trace reports); full blocks,
    // which have no node, are appended after them.
    t.nodes_.resize(nodes.size());
    struct VPending {
      std::uint32_t id;
      std::uint32_t corner[3];
      std::uint32_t size;
      std::uint32_t depth;
      std::uint32_t parent;
    };
    std::vector<VPending> stack;
    std::vector<bool> seen(nodes.size(), false);  // a malformed array must not loop
    if (vox->root() == Voxels::Root::interior && !nodes.empty()) {
      stack.push_back({static_cast<std::uint32_t>(nodes.size() - 1), {0, 0, 0}, dom.resolution, 0, kNone});
      seen.back() = true;
    }
    if (vox->root() == Voxels::Root::full) {
      StructureNode n;
      n.bounds = dom.box();
      n.leaf = true;
      t.nodes_.push_back(n);
    }
    while (!stack.empty()) {
      const VPending p = stack.back();
      stack.pop_back();
      if (p.id >= nodes.size()) continue;
      {
        StructureNode& n = t.nodes_[p.id];
        n.bounds = dom.block_box(p.corner[0], p.corner[1], p.corner[2], p.size);
        n.depth = p.depth;
        n.parent = p.parent;
      }
      const VoxelNode& vn = nodes[p.id];
      const std::uint32_t half = p.size / 2;
      for (int o = 7; o >= 0; --o) {
        if (!((vn.valid >> o) & 1u)) continue;
        std::uint32_t c[3];
        for (int a = 0; a < 3; ++a) c[a] = p.corner[a] + (((o >> a) & 1) ? half : 0);
        if ((vn.full >> o) & 1u) {
          StructureNode leaf;
          leaf.bounds = dom.block_box(c[0], c[1], c[2], half);
          leaf.depth = p.depth + 1;
          leaf.parent = p.id;
          leaf.leaf = true;
          t.nodes_.push_back(leaf);
        } else {
          const std::uint32_t child = vn.child(o);
          if (child < nodes.size() && !seen[child]) {
            seen[child] = true;
            stack.push_back({child, {c[0], c[1], c[2]}, half, p.depth + 1, p.id});
          }
        }
      }
    }
    t.finish(1.0f, 1.0f);
  } else if (const auto* grid = dynamic_cast<const Grid*>(&accel)) {
    t.kind_ = "grid";
    GridCells g;
    g.res = grid->resolution();
    g.bounds = grid->bounds();
    for (int a = 0; a < 3; ++a)
      for (int i = 0; i <= g.res[a]; ++i) g.planes[a].push_back(grid->plane(a, i));
    const auto start = grid->cell_start();
    g.counts.resize(start.empty() ? 0 : start.size() - 1);
    for (std::size_t c = 0; c < g.counts.size(); ++c) g.counts[c] = start[c + 1] - start[c];
    t.grid_ = std::move(g);
    t.max_depth_ = 1;
  }
  return t;
}

void StructureNodes::finish(float c_trav, float c_isect) {
  // Children lists (CSR by parent), depth and the SAH shares.
  child_start_.assign(nodes_.size() + 1, 0);
  for (const StructureNode& n : nodes_)
    if (n.parent < nodes_.size()) ++child_start_[n.parent + 1];
  for (std::size_t i = 0; i < nodes_.size(); ++i) child_start_[i + 1] += child_start_[i];
  children_.assign(child_start_.back(), 0);
  std::vector<std::uint32_t> fill(child_start_.begin(), child_start_.end() - 1);
  for (std::uint32_t i = 0; i < nodes_.size(); ++i)
    if (nodes_[i].parent < nodes_.size()) children_[fill[nodes_[i].parent]++] = i;

  // Primitives below each node: children before their parents, in the reverse of a breadth-first
  // order from the roots (a child's id is not always above its parent's: the voxel octree's root
  // comes last).
  std::vector<std::uint32_t> order;
  order.reserve(nodes_.size());
  for (std::uint32_t i = 0; i < nodes_.size(); ++i) {
    nodes_[i].prims_below = nodes_[i].leaf ? nodes_[i].prims : 0;
    if (nodes_[i].parent >= nodes_.size()) order.push_back(i);
  }
  for (std::size_t k = 0; k < order.size(); ++k)
    for (std::uint32_t c = child_start_[order[k]]; c < child_start_[order[k] + 1]; ++c) order.push_back(children_[c]);
  for (std::size_t k = order.size(); k-- > 0;)
    if (const std::uint32_t p = nodes_[order[k]].parent; p < nodes_.size())
      nodes_[p].prims_below += nodes_[order[k]].prims_below;

  max_depth_ = 0;
  double total = 0.0;
  const float root_area = nodes_.empty() ? 0.0f : nodes_.front().bounds.surface_area();
  // The voxel octree's root is its last interior node, not node 0.
  float area_ref = root_area;
  for (const StructureNode& n : nodes_)
    if (n.parent == kNone && n.depth == 0) area_ref = std::max(area_ref, n.bounds.surface_area());
  for (StructureNode& n : nodes_) {
    max_depth_ = std::max(max_depth_, n.depth);
    const float ratio = area_ref > 0.0f ? n.bounds.surface_area() / area_ref : 1.0f;
    n.sah_share = (n.leaf ? c_isect * static_cast<float>(n.prims) : c_trav) * ratio;
    total += n.sah_share;
  }
  if (total > 0.0)
    for (StructureNode& n : nodes_) n.sah_share = static_cast<float>(n.sah_share / total);
}

std::uint64_t StructureNodes::size() const {
  return grid_ ? grid_->counts.size() : nodes_.size();
}

std::optional<Aabb> StructureNodes::box(std::uint32_t id) const {
  if (grid_) {
    const auto& g = *grid_;
    if (id >= g.counts.size()) return std::nullopt;
    const int x = static_cast<int>(id % static_cast<std::uint32_t>(g.res[0]));
    const int y = static_cast<int>((id / static_cast<std::uint32_t>(g.res[0])) % static_cast<std::uint32_t>(g.res[1]));
    const int z = static_cast<int>(id / static_cast<std::uint32_t>(g.res[0] * g.res[1]));
    return Aabb{{g.planes[0][x], g.planes[1][y], g.planes[2][z]},
                {g.planes[0][x + 1], g.planes[1][y + 1], g.planes[2][z + 1]}};
  }
  if (id >= nodes_.size()) return std::nullopt;
  return nodes_[id].bounds;
}

std::string StructureNodes::describe(std::uint32_t id) const {
  const std::string word = grid_ ? "cell" : "node";
  const std::uint64_t n = size();
  if (id >= n) {
    if (n == 0)
      return "no " + word + " " + std::to_string(id) + ": " + (kind_.empty() ? "this structure" : kind_) +
             " has no nodes to show";
    return "no " + word + " " + std::to_string(id) + ": this " + kind_ + " has " + word + "s 0-" +
           std::to_string(n - 1);
  }
  const std::string name = word + " " + std::to_string(id);
  if (grid_) {
    const auto& g = *grid_;
    const std::uint32_t rx = static_cast<std::uint32_t>(g.res[0]), ry = static_cast<std::uint32_t>(g.res[1]);
    return name + " (x " + std::to_string(id % rx) + ", y " + std::to_string((id / rx) % ry) + ", z " +
           std::to_string(id / (rx * ry)) + "): " + count_of(g.counts[id], "primitive");
  }
  const StructureNode& node = nodes_[id];
  if (node.leaf)
    return name + ": a leaf at depth " + std::to_string(node.depth) + ", " + count_of(node.prims, "primitive");
  const std::size_t kids = children(id).size();
  return name + ": depth " + std::to_string(node.depth) + ", " + std::to_string(kids) +
         (kids == 1 ? " child, " : " children, ") + count_of(node.prims_below, "primitive") + " below";
}

std::span<const std::uint32_t> StructureNodes::children(std::uint32_t id) const {
  if (id >= nodes_.size() || child_start_.empty()) return {};
  return std::span<const std::uint32_t>(children_).subspan(child_start_[id], child_start_[id + 1] - child_start_[id]);
}

template <class F>
void StructureNodes::for_each_selected(const NodeSelection& sel, F&& add) const {
  if (grid_) {
    const auto& g = *grid_;
    if (sel.mode == BoxMode::subtree) {
      if (const auto b = box(sel.node)) add({*b, sel.node, 1, true, 0.0f});
      return;
    }
    // Depth 0: the grid's bounds; depth 1: its occupied cells (the leaves).
    const bool range = sel.mode == BoxMode::depth_range;
    const bool bounds = (sel.mode == BoxMode::depth || range) && sel.depth == 0;
    const bool cells = sel.mode == BoxMode::leaves || (sel.mode == BoxMode::depth && sel.depth == 1) ||
                       (range && sel.depth <= 1 && sel.depth_last >= 1);
    if (bounds) add({g.bounds, 0, 0, false, 1.0f});
    if (!cells) return;
    double total = 0.0;
    for (std::uint32_t c : g.counts) total += c;
    for (std::uint32_t c = 0; c < g.counts.size(); ++c)
      if (g.counts[c] > 0) add({*box(c), c, 1, true, total > 0.0 ? static_cast<float>(g.counts[c] / total) : 0.0f});
    return;
  }
  auto to_box = [&](std::uint32_t i) {
    const StructureNode& n = nodes_[i];
    return NodeBox{n.bounds, i, n.depth, n.leaf, n.sah_share, n.instance};
  };
  if (sel.mode == BoxMode::subtree) {
    if (sel.node >= nodes_.size()) return;
    std::vector<std::uint32_t> stack{sel.node};
    while (!stack.empty()) {
      const std::uint32_t i = stack.back();
      stack.pop_back();
      add(to_box(i));
      const auto kids = children(i);
      for (auto it = kids.rbegin(); it != kids.rend(); ++it) stack.push_back(*it);
    }
    return;
  }
  // Depth-first order from the roots, so boxes come parent before child
  // whatever the id layout (the voxel octree stores its root last).
  std::vector<std::uint32_t> stack;
  for (std::uint32_t i = nodes_.size(); i-- > 0;)
    if (nodes_[i].parent == kNone) stack.push_back(i);
  while (!stack.empty()) {
    const std::uint32_t i = stack.back();
    stack.pop_back();
    const StructureNode& n = nodes_[i];
    bool match = false;
    bool deeper = true;
    switch (sel.mode) {
      case BoxMode::depth:
        match = n.depth == sel.depth;
        deeper = n.depth < sel.depth;
        break;
      case BoxMode::depth_range:
        match = n.depth >= sel.depth && n.depth <= sel.depth_last;
        deeper = n.depth < sel.depth_last;
        break;
      case BoxMode::leaves:
        match = n.leaf;
        break;
      case BoxMode::subtree:
        break;
    }
    if (match) add(to_box(i));
    if (!deeper) continue;
    const auto kids = children(i);
    for (auto it = kids.rbegin(); it != kids.rend(); ++it) stack.push_back(*it);
  }
}

StructureNodes::Selection StructureNodes::select(const NodeSelection& sel, std::size_t limit) const {
  Selection out;
  for_each_selected(sel, [&](const NodeBox&) { ++out.matched; });
  if (out.matched <= limit) {
    out.boxes.reserve(out.matched);
    for_each_selected(sel, [&](const NodeBox& b) { out.boxes.push_back(b); });
    return out;
  }
  // More than `limit`: `limit` boxes spread evenly over the selection's
  // order (box floor(k * matched / limit) for k = 0, 1, ...), so that a cut
  // list thins the whole structure out instead of showing its first boxes
  // only (on the dragon's leaves: one half of the mesh covered, the other bare).
  out.truncated = true;
  out.boxes.reserve(limit);
  std::uint64_t index = 0;
  for_each_selected(sel, [&](const NodeBox& b) {
    const auto k = static_cast<unsigned __int128>(out.boxes.size());
    if (out.boxes.size() < limit && index == k * out.matched / limit) out.boxes.push_back(b);
    ++index;
  });
  return out;
}

StructureNodes::Selection select_blas_boxes(const Tlas& tlas, const NodeSelection& sel, std::size_t limit,
                                            int instance) {
  StructureNodes::Selection out;
  const auto instances = tlas.instances();
  if (instance >= 0 && static_cast<std::size_t>(instance) >= instances.size()) return out;
  const std::size_t first = instance >= 0 ? static_cast<std::size_t>(instance) : 0;
  const std::size_t last = instance >= 0 ? first + 1 : instances.size();
  // Each BLAS's selection once, in object space (instances share BLASes).
  std::vector<std::optional<std::vector<NodeBox>>> per_blas(tlas.blas_count());
  for (std::size_t i = first; i < last; ++i) {
    const TlasInstance& inst = instances[i];
    auto& picked = per_blas[inst.blas];
    if (!picked)
      picked = StructureNodes::of(tlas.blas(inst.blas)).select(sel, std::numeric_limits<std::size_t>::max()).boxes;
    out.matched += picked->size();
    if (out.truncated) continue;
    if (out.boxes.size() + picked->size() > limit && !out.boxes.empty()) {
      out.truncated = true;  // whole instances only
      continue;
    }
    for (const NodeBox& b : *picked) {
      if (out.boxes.size() >= limit) {
        out.truncated = true;
        break;
      }
      NodeBox w = b;
      w.bounds = corners_box(b.bounds, inst.to_world);
      w.instance = static_cast<std::uint32_t>(i);
      out.boxes.push_back(w);
    }
  }
  return out;
}

std::uint32_t blas_max_depth(const Tlas& tlas) {
  std::uint32_t d = 0;
  for (std::size_t b = 0; b < tlas.blas_count(); ++b) d = std::max(d, tlas.blas(b).build_stats().max_depth);
  return d;
}

}  // namespace accelviz
