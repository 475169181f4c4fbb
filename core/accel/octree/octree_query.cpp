// Octree traversal: a stack of (cell, segment) entries; an inner cell's
// segment is cut at its three mid-planes to list the octants the ray passes
// in front-to-back order, which are pushed in reverse.
#include <algorithm>
#include <type_traits>
#include <utility>

#include "core/accel/kdtree/spatial_traversal.h"
#include "core/accel/octree/octree.h"

namespace accelviz {

namespace {

struct OctantPiece {
  int octant;
  float t0, t1;
};

// The octants of `box` that the segment [t0, t1] passes, in the order the
// ray visits them (up to 8 when the ray lies in mid-planes): the segment is
// cut by the x mid-plane, each part by the y mid-plane, each of those by the
// z mid-plane. Each cut keeps the order, so the result is sorted by entry.
int order_octants(const Ray& ray, const Aabb& box, float t0, float t1, std::array<OctantPiece, 8>& out) {
  int n = 1;
  out[0] = {0, t0, t1};
  for (int a = 0; a < 3; ++a) {
    const float mid = 0.5f * (box.lo[a] + box.hi[a]);  // the same expression as Octree::child_box
    std::array<OctantPiece, 8> next{};
    int m = 0;
    for (int i = 0; i < n; ++i) {
      std::array<spatial::SidePiece, 2> side;
      const int k = spatial::split_at_plane(ray.origin[a], ray.inv_dir[a], mid, out[i].t0, out[i].t1,
                                            spatial::kPlaneSlackRel, true, side);
      for (int j = 0; j < k; ++j) next[m++] = {out[i].octant | (side[j].side << a), side[j].t0, side[j].t1};
    }
    out = next;
    n = m;
  }
  return n;
}

}  // namespace

template <bool kCollect, bool kAnyHit>
Hit Octree::traverse(const Ray& ray, const QueryOptions& qo, RayStats* stats, VisitTrace* trace) const {
  if (nodes_.empty() || !spatial::is_traversable(ray)) return Hit{};

  SlabInterval iv;
  const bool in_box = intersect_slab(root_, ray, iv);
  spatial::record_root_test<kCollect>(in_box, iv.t_entry, iv.t_exit, stats, trace);
  if (!in_box) return Hit{};

  struct Entry {
    std::uint32_t node;
    float t0, t1;
    Aabb box;
  };
  // Each level leaves at most 7 siblings waiting.
  Entry stack[7 * kOctreeMaxDepth + 8];
  int sp = 0;
  stack[sp++] = {0, iv.t_entry, iv.t_exit, root_};

  spatial::CellPrimTests<kCollect, kAnyHit> prims(ray, qo.triangle_test, opts_.mailboxing, tris_, stats, trace);

  while (sp > 0) {
    const Entry e = stack[--sp];
    // A cell entered beyond the closest hit cannot hold a nearer one. (Not
    // the end of the search: a ray lying in a mid-plane leaves siblings with
    // equal segments, so the stack is not strictly sorted by entry.)
    if (e.t0 > prims.tmax()) {
      if constexpr (kCollect) {
        if (stats) ++stats->nodes_culled;
        if (trace) trace->steps.push_back({VisitStep::Kind::node_culled, e.node, e.t0, e.t1});
      }
      continue;
    }
    if constexpr (kCollect) {
      if (stats) ++stats->nodes_visited;
      if (trace) trace->steps.push_back({VisitStep::Kind::node_entered, e.node, e.t0, e.t1});
    }
    const OctreeNode& n = nodes_[e.node];
    if (!n.is_leaf()) {
      std::array<OctantPiece, 8> piece;
      const int k = order_octants(ray, e.box, e.t0, e.t1, piece);
      if (!qo.ordered) {  // fixed octant order (insertion sort of at most 8)
        for (int i = 1; i < k; ++i)
          for (int j = i; j > 0 && piece[j - 1].octant > piece[j].octant; --j) std::swap(piece[j - 1], piece[j]);
      }
      for (int i = k - 1; i >= 0; --i) {
        const std::uint32_t child = n.index + static_cast<std::uint32_t>(piece[i].octant);
        if (nodes_[child].count == 0) {  // empty leaf: nothing to do there
          if constexpr (kCollect) {
            if (stats) ++stats->empty_cells;
          }
          continue;
        }
        stack[sp++] = {child, piece[i].t0, piece[i].t1, child_box(e.box, piece[i].octant)};
      }
      continue;
    }
    // Leaf: test against [tmin, closest so far]; a hit beyond this cell's
    // exit is kept as a candidate but does not end the search.
    if (prims.test(prim_refs_.data() + n.index, n.count)) return prims.result();
  }
  return prims.result();
}

Hit Octree::closest_hit(const Ray& ray, const QueryOptions& qo, RayStats* stats, VisitTrace* trace) const {
  if (stats || trace) return traverse<true, false>(ray, qo, stats, trace);
  return traverse<false, false>(ray, qo, nullptr, nullptr);
}

bool Octree::any_hit(const Ray& ray, const QueryOptions& qo, RayStats* stats) const {
  if (stats) return traverse<true, true>(ray, qo, stats, nullptr).valid();
  return traverse<false, true>(ray, qo, nullptr, nullptr).valid();
}

}  // namespace accelviz
