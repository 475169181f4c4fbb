// Sparse voxel octree march: a stack of (octant, segment) entries, each
// interior octant's segment cut at its three mid-planes to list its children
// front to back; empty children are skipped whole (the empty-space skipping
// that the hierarchy buys), the first full one is the hit.
//
// Exactness against dense_voxel_march: planes are VoxelDomain::plane(),
// crossings (plane - o) · inv_dir, compared as totally ordered events (see
// Event), and a ray lying in a plane belongs to the upper side. With those,
// the octants visited are the dense march's voxels grouped into blocks, and
// the entry distance, face and index of the first occupied voxel come out
// bit for bit the same.
#include <array>
#include <cmath>
#include <cstdint>

#include "core/accel/kdtree/spatial_traversal.h"
#include "core/accel/voxels/voxels.h"

namespace accelviz {

namespace {

// A plane crossing (or the segment's start or end) as an event with a total
// order: by t, then by axis, then by the plane's position along the ray.
// The dense march steps through crossings in exactly this order (at equal t
// it steps the lowest axis first), so deciding every visit by comparing
// events, never bare t values, makes the sparse march see the very voxels
// the dense one sees even where crossings tie in float.
struct Event {
  float t;
  int axis;            // -1: the segment's start, 3: its end
  std::int64_t order;  // plane index along the ray (negated for a negative direction)
};
bool before(const Event& a, const Event& b) {
  if (a.t != b.t) return a.t < b.t;
  if (a.axis != b.axis) return a.axis < b.axis;
  return a.order < b.order;
}

struct Piece {
  int octant;
  Event start, end;  // the part of the segment inside the octant
  Event line;        // where the ray's line enters the octant's box (the latest near-plane crossing)
};

// Cuts the block's segment at its mid-planes (x, then y, then z), keeping
// the visiting order. An octant is visited when its start event precedes
// its end event; one on the far side of a mid-plane is entered (by the
// line) through that plane. A ray parallel to a mid-plane stays on its
// origin's side, the upper one when it lies in the plane.
int order_octants(const Ray& ray, const VoxelDomain& d, const std::uint32_t corner[3], std::uint32_t half,
                  const Piece& whole, std::array<Piece, 8>& out) {
  int n = 1;
  out[0] = whole;
  out[0].octant = 0;
  for (int a = 0; a < 3; ++a) {
    const std::uint32_t index = corner[a] + half;
    const float plane = d.plane(a, index);
    const float o = ray.origin[a], inv = ray.inv_dir[a];
    if (std::isinf(inv)) {
      if (o >= plane)
        for (int i = 0; i < n; ++i) out[i].octant |= 1 << a;
      continue;
    }
    const Event cross{(plane - o) * inv, a, inv > 0.0f ? std::int64_t{index} : -std::int64_t{index}};
    const int near_side = inv > 0.0f ? 0 : 1;
    std::array<Piece, 8> next{};
    int m = 0;
    for (int i = 0; i < n; ++i) {
      const Piece& p = out[i];
      if (before(p.start, cross)) {
        Piece q = p;
        q.octant |= near_side << a;
        if (before(cross, q.end)) q.end = cross;  // the crossing may lie beyond the segment
        next[m++] = q;
      }
      if (before(cross, p.end)) {
        Piece q = p;
        q.octant |= (1 - near_side) << a;
        if (before(q.start, cross)) q.start = cross;  // or before it (crossed before tmin)
        if (before(q.line, cross)) q.line = cross;
        next[m++] = q;
      }
    }
    out = next;
    n = m;
  }
  return n;
}

}  // namespace

template <bool kCollect>
Hit Voxels::traverse(const Ray& ray, RayStats* stats, VisitTrace* trace) const {
  Hit hit;
  if (root_ == Root::empty || !spatial::is_traversable(ray)) return hit;
  VoxelSegment seg;
  const bool in_domain = voxel_segment(domain_, ray, seg);
  spatial::record_root_test<kCollect>(in_domain, seg.t0, seg.t1, stats, trace);
  if (!in_domain) return hit;

  struct Entry {
    std::uint32_t node;  // interior: node index; full: unused
    bool full;
    std::uint32_t corner[3];
    std::uint32_t size;
    Piece piece;
  };
  Entry stack[8 * (kVoxelMaxLevel + 1) + 8];
  int sp = 0;
  Event line{seg.line_t, seg.axis, 0};
  if (seg.axis >= 0 && ray.inv_dir[seg.axis] < 0.0f) line.order = -static_cast<std::int64_t>(domain_.resolution);
  const Piece whole{0, {seg.t0, -1, 0}, {seg.t1, 3, 0}, line};
  stack[sp++] = {root_ == Root::interior ? static_cast<std::uint32_t>(nodes_.size() - 1) : 0u,
                 root_ == Root::full,
                 {0, 0, 0},
                 domain_.resolution,
                 whole};

  while (sp > 0) {
    Entry e = stack[--sp];
    if constexpr (kCollect) {
      if (stats) ++stats->nodes_visited;
    }
    if (e.full) {
      // The first occupied voxel: inside a full block, the voxel the ray is
      // in at the block's entry, found by descending along the first octant.
      for (std::uint32_t size = e.size; size > 1; size /= 2) {
        std::array<Piece, 8> piece;
        order_octants(ray, domain_, e.corner, size / 2, e.piece, piece);
        e.piece = piece[0];
        for (int a = 0; a < 3; ++a)
          if ((piece[0].octant >> a) & 1) e.corner[a] += size / 2;
      }
      hit.t = std::max(seg.t0, e.piece.line.t);
      hit.ng = voxel_face_normal(ray, e.piece.line.axis);
      hit.prim = domain_.linear(e.corner[0], e.corner[1], e.corner[2]);
      if constexpr (kCollect) {
        if (trace) trace->steps.push_back({VisitStep::Kind::prim_hit, hit.prim, hit.t, kInfinity});
      }
      return hit;
    }
    if constexpr (kCollect) {
      if (trace) trace->steps.push_back({VisitStep::Kind::node_entered, e.node, e.piece.start.t, e.piece.end.t});
    }
    const VoxelNode& n = nodes_[e.node];
    const std::uint32_t half = e.size / 2;
    std::array<Piece, 8> piece;
    const int k = order_octants(ray, domain_, e.corner, half, e.piece, piece);
    for (int i = k - 1; i >= 0; --i) {
      const int o = piece[i].octant;
      if (!((n.valid >> o) & 1u)) {  // empty octant: skipped whole
        if constexpr (kCollect) {
          if (stats) ++stats->empty_cells;
        }
        continue;
      }
      const bool full = (n.full >> o) & 1u;
      Entry c{full ? 0u : n.child(o), full, {e.corner[0], e.corner[1], e.corner[2]}, half, piece[i]};
      for (int a = 0; a < 3; ++a)
        if ((o >> a) & 1) c.corner[a] += half;
      stack[sp++] = c;
    }
  }
  return hit;
}

Hit Voxels::closest_hit(const Ray& ray, const QueryOptions&, RayStats* stats, VisitTrace* trace) const {
  if (stats || trace) return traverse<true>(ray, stats, trace);
  return traverse<false>(ray, nullptr, nullptr);
}

bool Voxels::any_hit(const Ray& ray, const QueryOptions&, RayStats* stats) const {
  if (stats) return traverse<true>(ray, stats, nullptr).valid();
  return traverse<false>(ray, nullptr, nullptr).valid();
}

}  // namespace accelviz
