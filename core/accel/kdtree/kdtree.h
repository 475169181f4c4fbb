#pragma once
// K-D tree: a binary space partition by axis-aligned planes, each leaf
// holding the primitives that overlap its cell (a primitive straddling a
// plane is referenced on both sides). Built with the surface area heuristic
// over the exact event sweep of Wald & Havran ("On building fast kd-trees for
// ray tracing, and on doing that in O(N log N)", RT 2006) in its O(N log² N)
// form (events sorted per node), with primitives clipped to the node's box
// ("perfect splits", Havran 2000) so that a triangle only counts on the side
// of a plane it really reaches. Stored as a flat array of 8-byte nodes (as in
// pbrt-v3's KdAccelNode); traversed front to back with a small stack (Havran's
// TA_rec / pbrt), mailboxed.
#include "core/accel/accel.h"
#include "core/math/aabb.h"

#include <bit>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace accelviz {

struct KdTreeOptions {
  float cost_traversal = 1.0f;   ///< C_trav: cost of one inner-node step (> 0, finite)
  float cost_intersect = 1.5f;   ///< C_isect: cost of one ray-triangle test (> 0, finite)
  int max_depth = 0;             ///< deepest leaf (root = 0); 0 = auto: round(8 + 1.3·log2 N), at most 64
  int max_leaf_size = 2;         ///< a node with <= this many primitives is always a leaf (>= 1)
  float empty_bonus = 0.2f;      ///< SAH discount (0..1) for a split with an empty side: cost·(1 - bonus)
  bool perfect_splits = true;    ///< clip triangles to the node box for events and classification (else clamp bounds)
  bool mailboxing = true;        ///< skip primitives this ray already tested (a 16-entry hashed mailbox)
  unsigned threads = 0;          ///< build threads, 0 = all hardware threads; the tree is the same for any count
};

/// Throws std::invalid_argument naming the offending option.
void validate(const KdTreeOptions& opts);

/// Deepest leaf any K-D tree may have (the traversal stack holds this many entries).
inline constexpr int kKdMaxDepth = 64;

/// One node, 8 bytes. `word` is the split position (float bits) of an inner
/// node or the offset into prim_refs() of a leaf; `bits` holds the axis in its
/// two low bits (3 = leaf) and above them the index of the "above" child
/// (inner; the "below" child is the next node) or the primitive count (leaf).
struct KdNode {
  std::uint32_t word = 0;
  std::uint32_t bits = 3;

  bool is_leaf() const { return (bits & 3u) == 3u; }
  int axis() const { return static_cast<int>(bits & 3u); }
  float split() const { return std::bit_cast<float>(word); }
  std::uint32_t above_child() const { return bits >> 2; }
  std::uint32_t prim_offset() const { return word; }
  std::uint32_t prim_count() const { return bits >> 2; }

  static KdNode inner(int axis, float split, std::uint32_t above) {
    return {std::bit_cast<std::uint32_t>(split), (above << 2) | static_cast<std::uint32_t>(axis)};
  }
  static KdNode leaf(std::uint32_t offset, std::uint32_t count) { return {offset, (count << 2) | 3u}; }
};
static_assert(sizeof(KdNode) == 8, "K-D tree node must stay 8 bytes");

class KdTree final : public Accelerator {
 public:
  /// Builds over `triangles` (copied; primitive ids are indices into this
  /// span). Triangles with non-finite coordinates are left out (they cannot
  /// be hit). Throws std::invalid_argument for bad options, BuildCancelled
  /// when `progress` returns false.
  KdTree(std::span<const Triangle> triangles, const KdTreeOptions& opts = {}, const ProgressCallback& progress = {});

  std::string name() const override { return "kdtree"; }
  Hit closest_hit(const Ray& ray, const QueryOptions& opts, RayStats* stats = nullptr,
                  VisitTrace* trace = nullptr) const override;
  bool any_hit(const Ray& ray, const QueryOptions& opts, RayStats* stats = nullptr) const override;
  /// node_count, leaf_count, max_depth, avg_leaf_depth, memory_bytes (nodes +
  /// leaf lists), sah_cost; extra: "references" (leaf entries, counting
  /// duplicates), "duplication" (references / primitives), "empty_leaves",
  /// "max_depth_limit" (the resolved max_depth).
  const BuildStats& build_stats() const override { return stats_; }

  std::span<const KdNode> nodes() const { return nodes_; }
  /// Leaf lists index this array; its values are primitive ids (scene order).
  std::span<const std::uint32_t> prim_refs() const { return prim_refs_; }
  /// Box of the root (bounds of the finite triangles; empty without any).
  const Aabb& bounds() const { return bounds_; }
  const KdTreeOptions& options() const { return opts_; }

 private:
  template <bool kCollect, bool kAnyHit>
  Hit traverse(const Ray& ray, const QueryOptions& qo, RayStats* stats, VisitTrace* trace) const;

  std::vector<Triangle> tris_;
  std::vector<KdNode> nodes_;
  std::vector<std::uint32_t> prim_refs_;
  Aabb bounds_;
  KdTreeOptions opts_;
  BuildStats stats_;
};

}  // namespace accelviz
