// K-D tree traversal: front to back with a stack of far children (Havran's
// TA_rec, as in pbrt-v3's KdTreeAccel::Intersect), mailboxed.
#include <type_traits>

#include "core/accel/kdtree/kdtree.h"
#include "core/accel/kdtree/spatial_traversal.h"

namespace accelviz {

template <bool kCollect, bool kAnyHit>
Hit KdTree::traverse(const Ray& ray, const QueryOptions& qo, RayStats* stats, VisitTrace* trace) const {
  if (nodes_.empty() || !spatial::is_traversable(ray)) return Hit{};

  // 1. Clip the ray to the root box (robust slab test).
  SlabInterval iv;
  const bool in_box = intersect_slab(bounds_, ray, iv);
  spatial::record_root_test<kCollect>(in_box, iv.t_entry, iv.t_exit, stats, trace);
  if (!in_box) return Hit{};

  struct Entry {
    std::uint32_t node;
    float t0, t1;
  };
  Entry stack[kKdMaxDepth + 1];
  int sp = 0;

  spatial::CellPrimTests<kCollect, kAnyHit> prims(ray, qo.triangle_test, opts_.mailboxing, tris_, stats, trace);

  std::uint32_t node = 0;
  float t0 = iv.t_entry, t1 = iv.t_exit;
  for (;;) {
    // 2. Descend to a leaf, nearer child first; the farther child waits on
    //    the stack with its part of the segment.
    bool reached_leaf = true;
    for (;;) {
      if constexpr (kCollect) {
        if (stats) ++stats->nodes_visited;
        if (trace) trace->steps.push_back({VisitStep::Kind::node_entered, node, t0, t1});
      }
      const KdNode& n = nodes_[node];
      if (n.is_leaf()) break;
      const int axis = n.axis();
      std::array<spatial::SidePiece, 2> piece;
      const int count = spatial::split_at_plane(ray.origin[axis], ray.inv_dir[axis], n.split(), t0, t1,
                                                spatial::kPlaneSlackRel, true, piece);
      if (count == 0) {
        reached_leaf = false;
        break;
      }
      if (count == 2) {
        if (!qo.ordered && piece[0].side == 1) std::swap(piece[0], piece[1]);  // fixed order: below first
        stack[sp++] = {piece[1].side ? n.above_child() : node + 1, piece[1].t0, piece[1].t1};
      }
      node = piece[0].side ? n.above_child() : node + 1;
      t0 = piece[0].t0;
      t1 = piece[0].t1;
    }

    // 3. Test the leaf's primitives against [tmin, closest so far]. A hit
    //    beyond this leaf's exit is kept but does not end the search.
    if (reached_leaf) {
      const KdNode& leaf = nodes_[node];
      if (prims.test(prim_refs_.data() + leaf.prim_offset(), leaf.prim_count())) return prims.result();
    }

    // 4. Next waiting node, unless it starts beyond the closest hit. The
    //    stack is nearly sorted by entry, but not quite: a ray lying in a
    //    split plane waits with its whole segment for the second child, below
    //    entries that start later. So a culled entry is skipped, not taken as
    //    the end of the search.
    bool resumed = false;
    while (sp > 0) {
      const Entry e = stack[--sp];
      if (e.t0 > prims.tmax()) {
        if constexpr (kCollect) {
          if (stats) ++stats->nodes_culled;
          if (trace) trace->steps.push_back({VisitStep::Kind::node_culled, e.node, e.t0, e.t1});
        }
        continue;
      }
      node = e.node;
      t0 = e.t0;
      t1 = e.t1;
      resumed = true;
      break;
    }
    if (!resumed) break;
  }
  return prims.result();
}

Hit KdTree::closest_hit(const Ray& ray, const QueryOptions& qo, RayStats* stats, VisitTrace* trace) const {
  if (stats || trace) return traverse<true, false>(ray, qo, stats, trace);
  return traverse<false, false>(ray, qo, nullptr, nullptr);
}

bool KdTree::any_hit(const Ray& ray, const QueryOptions& qo, RayStats* stats) const {
  if (stats) return traverse<true, true>(ray, qo, stats, nullptr).valid();
  return traverse<false, true>(ray, qo, nullptr, nullptr).valid();
}

}  // namespace accelviz
