#pragma once
// Bounding volume hierarchy: a binary tree of axis-aligned boxes over the
// scene's primitives, stored as a flat array of 32-byte nodes (no pointer
// tree), built top-down with a surface area heuristic (Goldsmith & Salmon
// 1987, MacDonald & Booth 1990) or by median splits, traversed with a small
// fixed-size stack.
//
// The builder works on primitive bounds and centroids only (build_bvh), so
// the two-level structure reuses it over instance bounds; class Bvh wraps it
// for triangles and adds the queries and refitting.
#include "core/accel/accel.h"
#include "core/math/aabb.h"
#include "core/util/huge_page_allocator.h"

#include <memory>

#include <glm/glm.hpp>

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace accelviz {

namespace bvh_detail {
struct WideBvh;
struct WideBvh8;
struct TriBlock4;
}

/// How a node's primitives are divided between its two children.
enum class BvhSplitter {
  binned_sah,  ///< SAH evaluated at bucket boundaries on all three axes (Wald 2007)
  exact_sah,   ///< SAH evaluated between every pair of neighbours in sorted order on each axis (full sweep)
  median,      ///< equal counts on the axis of largest centroid extent (no SAH)
  lbvh,        ///< Morton-code order cut at the highest differing bit (Karras 2012; no SAH, fastest build)
};

/// Short name of a splitter ("binned", "exact", "median", "lbvh").
const char* to_string(BvhSplitter s);

struct BvhOptions {
  BvhSplitter splitter = BvhSplitter::binned_sah;  ///< split strategy
  int buckets = 32;              ///< binned SAH bucket count B, 2..256
  bool small_node_buckets = true;  ///< binned SAH: min(B, 4 + n/20) buckets on a node of n primitives (Embree's rule: cheaper small nodes); false: B everywhere
  int max_leaf_size = 4;         ///< a node with <= this many primitives always becomes a leaf (1..255)
  int leaf_size_cap = 16;        ///< SAH splitters may keep up to this many primitives in a leaf when that is cheaper than splitting; above it a node is always split (max_leaf_size..255)
  float cost_traversal = 1.0f;   ///< C_trav: cost of visiting an inner node (> 0, finite)
  float cost_intersect = 1.0f;   ///< C_isect: cost of one ray-primitive test (> 0, finite)
  unsigned threads = 0;          ///< build threads, 0 = all hardware threads; the node array is identical for any count
  bool compute_epo = true;       ///< Bvh only: compute the EPO metric into build_stats().extra["epo"] (costs a pass over the tree per triangle)
  bool wide_traversal = true;    ///< Bvh only: uninstrumented queries walk a wide collapse of the tree (faster); statistics and traces always walk the binary tree
  int wide_width = 0;            ///< Bvh only: width of that collapse: 0 = 8 (AVX2) where the CPU has AVX2 and FMA, else 4 (SSE); 4; or 8 (falls back to 4 without them)
  int wide_merge_blocks = -1;    ///< Bvh only: the collapse makes one leaf slot of a binary subtree whose leaves fill at most this many triangle blocks (0: never; -1: 2 when the triangle blocks take 16 MiB or more, else 0); -1..63
};

/// Throws std::invalid_argument naming the offending option when `opts` is out of range.
void validate(const BvhOptions& opts);

/// One node, 32 bytes. Inner node (count == 0): children at index and
/// index + 1. Leaf (count > 0): primitives prim_indices[index .. index+count).
/// Children are always stored after their parent, so a reverse sweep of the
/// array visits children before parents (used by refit).
struct BvhNode {
  Aabb bounds;
  std::uint32_t index = 0;
  std::uint32_t count = 0;

  bool is_leaf() const { return count > 0; }
};
static_assert(sizeof(BvhNode) == 32, "BVH node must stay 32 bytes (two per cache line)");

/// Deepest node the builder creates (root at depth 0); traversal stacks hold this many entries.
inline constexpr std::uint32_t kBvhMaxDepth = 64;

/// What build_bvh produces: the node array (root at 0; empty when there are
/// no primitives), the primitive order the leaves refer to, and the figures
/// that do not need the primitives themselves (sah_cost, depths, counts,
/// memory of nodes + indices, build time).
struct BvhTopology {
  HugePageVector<BvhNode> nodes;
  HugePageVector<std::uint32_t> prim_indices;
  BuildStats stats;
};

/// Builds a BVH over boxes. `bounds[i]` and `centroids[i]` describe primitive
/// i (the sizes must match). Centroids drive the binning and partitioning;
/// bounds drive the SAH and the node boxes. Throws std::invalid_argument for
/// bad options or mismatched spans, BuildCancelled when `progress` returns false.
BvhTopology build_bvh(std::span<const Aabb> bounds, std::span<const glm::vec3> centroids,
                      const BvhOptions& opts = {}, const ProgressCallback& progress = {});

/// A BVH over triangles: build_bvh plus the triangles in leaf order, stored
/// once as blocks of four (bvh_tri4.h; each binary leaf starts a block),
/// which every traversal reads: the binary one (statistics, traces) through
/// a per-node first-block index, the wide fast path through its leaf slots.
/// The triangles must be finite (Scene::flatten drops the others): a NaN
/// vertex makes NaN boxes, which can hide other triangles from every walk.
class Bvh final : public Accelerator {
 public:
  Bvh(std::span<const Triangle> triangles, const BvhOptions& opts = {}, const ProgressCallback& progress = {});
  ~Bvh() override;
  /// A deep copy (nodes, triangle blocks, the wide copy): what a two-level
  /// structure refits when the BLAS is shared with a snapshot (Tlas::snapshot).
  Bvh(const Bvh& other);
  Bvh(Bvh&&) noexcept;
  Bvh& operator=(Bvh&&) noexcept;

  std::string name() const override { return "bvh"; }
  Hit closest_hit(const Ray& ray, const QueryOptions& opts, RayStats* stats = nullptr,
                  VisitTrace* trace = nullptr) const override;
  bool any_hit(const Ray& ray, const QueryOptions& opts, RayStats* stats = nullptr) const override;
  const BuildStats& build_stats() const override { return stats_; }
  /// Packets walk the wide copy (bvh_packet_traverse.inl); without one
  /// (wide_traversal off) the packet queries answer per ray.
  bool has_packets() const override { return wide_ != nullptr || wide8_ != nullptr; }

  std::span<const BvhNode> nodes() const { return nodes_; }
  /// Leaf ranges index this array; its values are primitive ids in scene order.
  std::span<const std::uint32_t> prim_indices() const { return prim_indices_; }
  /// Number of triangles the tree was built over.
  std::size_t triangle_count() const { return prim_indices_.size(); }
  /// A copy of the triangles in leaf order: [k] is scene triangle
  /// prim_indices()[k] (O(triangles); the tree keeps them only as blocks).
  std::vector<Triangle> copy_leaf_triangles() const;
  /// Leaf-order positions [first, last) of copy_leaf_triangles() only (a subtree's triangles).
  std::vector<Triangle> copy_leaf_triangles(std::uint32_t first, std::uint32_t last) const;
  const BvhOptions& options() const { return opts_; }

  /// After the vertices moved (same triangle count, same order as at build):
  /// recomputes every box bottom-up in O(nodes) without changing the
  /// topology, then sah_cost (and epo when enabled), so the degradation
  /// against a fresh build can be shown. Throws std::invalid_argument on a
  /// count mismatch.
  void refit(std::span<const Triangle> moved_triangles);

 protected:
  /// With stats: several rays walked in turns (the same hits and counters as
  /// closest_hit per ray) so that one ray's memory waits overlap another's
  /// work: what counted heatmaps and counting passes run. Without: the fast
  /// path per ray.
  void closest_hits_span(std::span<const Ray> rays, std::span<Hit> hits, const QueryOptions& qo,
                         std::span<RayStats> stats) const override;
  void closest_packets_span(std::span<const Ray> rays, std::span<Hit> hits, const QueryOptions& qo) const override;
  void any_packets_span(std::span<const Ray> rays, std::span<std::uint8_t> occluded,
                        const QueryOptions& qo) const override;

 private:
  /// With compute_epo: epo (and epo_ms) over `triangles` in scene order;
  /// `progress` may cancel it (BuildCancelled), as it may the build.
  void update_epo(std::span<const Triangle> triangles, const ProgressCallback& progress = {});

  HugePageVector<BvhNode> nodes_;
  HugePageVector<std::uint32_t> prim_indices_;
  HugePageVector<bvh_detail::TriBlock4> blocks_;  ///< the triangles, four per block, each leaf from a new block
  HugePageVector<std::uint32_t> leaf_block_;      ///< per binary node: a leaf's first block (unused for inner nodes)
  std::unique_ptr<bvh_detail::WideBvh> wide_;    ///< 4-wide copy for the fast path (null when not used)
  std::unique_ptr<bvh_detail::WideBvh8> wide8_;  ///< 8-wide copy for the fast path (null when not used)
  BvhOptions opts_;
  BuildStats stats_;
};

}  // namespace accelviz
