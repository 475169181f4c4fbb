#pragma once
// Adaptive octree: a cube around the scene, split into eight equal octants
// wherever a cell holds more than max_leaf_size triangles (Glassner, "Space
// Subdivision for Fast Ray Tracing", IEEE CG&A 1984). A triangle is
// referenced by every child its exact overlap touches. Flat array of 8-byte
// nodes, eight siblings stored together; cell boxes are not stored but
// recomputed by halving during traversal (build and traversal use the very
// same float expressions, so they agree on every plane). Children are
// visited front to back by cutting the ray's segment at the three mid-planes
// in turn, which yields the octants in the order of Revelles, Ureña &
// Lastra's parametric traversal ("An Efficient Parametric Algorithm for
// Octree Traversal", WSCG 2000) without its lookup tables.
#include "core/accel/accel.h"
#include "core/math/aabb.h"

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace accelviz {

struct OctreeOptions {
  int max_depth = 10;      ///< deepest cell (root = 0), 0..16
  int max_leaf_size = 8;   ///< a cell with more triangles than this is split (while depth < max_depth), >= 1
  bool mailboxing = true;  ///< skip primitives this ray already tested (a 16-entry hashed mailbox)
  bool cost_termination = true;  ///< also stop where the SAH rates the split no cheaper than the leaf: 1 + Σ n_child / 4 >= n (stops runaway splitting where triangles cross)
  unsigned threads = 0;          ///< build threads, 0 = all hardware threads; the tree is the same for any count
};

/// Deepest octree any options may ask for.
inline constexpr int kOctreeMaxDepth = 16;

/// Throws std::invalid_argument naming the offending option.
void validate(const OctreeOptions& opts);

/// One node, 8 bytes. Inner node (count == kInner): its eight children are
/// nodes[index + octant], octant bit a set = upper half on axis a. Leaf:
/// primitives prim_refs[index .. index + count) (count 0 = empty cell).
struct OctreeNode {
  static constexpr std::uint32_t kInner = 0xFFFFFFFFu;
  std::uint32_t index = 0;
  std::uint32_t count = 0;

  bool is_leaf() const { return count != kInner; }
};
static_assert(sizeof(OctreeNode) == 8, "octree node must stay 8 bytes");

class Octree final : public Accelerator {
 public:
  /// Builds over `triangles` (copied; primitive ids are indices into this
  /// span); triangles with non-finite coordinates are left out. Throws
  /// std::invalid_argument for bad options, BuildCancelled when `progress`
  /// returns false.
  Octree(std::span<const Triangle> triangles, const OctreeOptions& opts = {}, const ProgressCallback& progress = {});

  std::string name() const override { return "octree"; }
  /// RayStats: nodes_visited = cells entered (inner and non-empty leaves),
  /// empty_cells = empty leaves the ray passes through (skipped at no cost),
  /// prim_tests, repeated_prim_tests, nodes_culled, box_tests = 1 (root).
  /// QueryOptions::ordered = false visits children in fixed octant order.
  Hit closest_hit(const Ray& ray, const QueryOptions& opts, RayStats* stats = nullptr,
                  VisitTrace* trace = nullptr) const override;
  bool any_hit(const Ray& ray, const QueryOptions& opts, RayStats* stats = nullptr) const override;
  /// node_count, leaf_count, max_depth, avg_leaf_depth, memory_bytes (nodes +
  /// leaf lists), sah_cost (with C_trav = C_isect = 1, for comparison with
  /// the trees); extra: "references", "duplication", "empty_leaves".
  const BuildStats& build_stats() const override { return stats_; }

  std::span<const OctreeNode> nodes() const { return nodes_; }
  std::span<const std::uint32_t> prim_refs() const { return prim_refs_; }
  /// The root cube (contains every finite triangle; empty without any).
  const Aabb& root_box() const { return root_; }
  /// Box of child `octant` of a cell `box`, exactly as build and traversal compute it.
  static Aabb child_box(const Aabb& box, int octant) {
    const glm::vec3 mid = 0.5f * (box.lo + box.hi);
    Aabb c;
    for (int a = 0; a < 3; ++a) {
      const bool upper = (octant >> a) & 1;
      c.lo[a] = upper ? mid[a] : box.lo[a];
      c.hi[a] = upper ? box.hi[a] : mid[a];
    }
    return c;
  }
  const OctreeOptions& options() const { return opts_; }

 private:
  template <bool kCollect, bool kAnyHit>
  Hit traverse(const Ray& ray, const QueryOptions& qo, RayStats* stats, VisitTrace* trace) const;

  std::vector<Triangle> tris_;
  std::vector<OctreeNode> nodes_;
  std::vector<std::uint32_t> prim_refs_;
  Aabb root_;
  OctreeOptions opts_;
  BuildStats stats_;
};

}  // namespace accelviz
