#pragma once
// Sparse voxel occupancy: the triangles' surfaces voxelized at 2^level voxels
// per axis over a cube around the scene, stored as a sparse octree in which
// empty subtrees take no storage and subtrees that are entirely occupied are
// collapsed into one "full" bit of their parent (the child masks of Laine &
// Karras, "Efficient Sparse Voxel Octrees", I3D 2010, without their contours).
// Rays march through it front to back, skipping empty octants at whatever
// level they are empty, and stop at the first occupied voxel.
//
// What a hit means here: not a triangle but a voxel. Hit::t is where the
// ray's line enters the first occupied voxel (clamped to tmin when the ray
// starts inside it), Hit::ng the normal of the face it enters through (the
// axis of entry, facing against the ray), Hit::prim the linear voxel index
// domain().linear(x, y, z) = x + R·(y + R·z), R = 2^level; u = v = 0. The
// reference for these answers is dense_voxel_march() over the same occupancy.
#include "core/accel/accel.h"
#include "core/accel/voxels/dense_voxels.h"
#include "core/accel/voxels/voxel_domain.h"

#include <bit>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace accelviz {

struct VoxelOptions {
  int level = 7;  ///< voxels per axis = 2^level, 0..10
};

/// Throws std::invalid_argument naming the offending option.
void validate(const VoxelOptions& opts);

/// One interior node of the sparse octree, 8 bytes. Octant o is empty when
/// bit o of `valid` is clear, fully occupied when it is set in `full` too
/// (no node stored), and an interior node otherwise; the interior children
/// are stored together in octant order from `first_child`.
struct VoxelNode {
  std::uint32_t first_child = 0;
  std::uint8_t valid = 0;
  std::uint8_t full = 0;
  std::uint16_t unused = 0;

  std::uint8_t interior() const { return static_cast<std::uint8_t>(valid & ~full); }
  /// Index of interior child `octant` (which must be interior).
  std::uint32_t child(int octant) const {
    return first_child + static_cast<std::uint32_t>(std::popcount(static_cast<unsigned>(interior()) & ((1u << octant) - 1u)));
  }
};
static_assert(sizeof(VoxelNode) == 8, "voxel node must stay 8 bytes");

class Voxels final : public Accelerator {
 public:
  /// Voxelizes `triangles` (not kept). Throws std::invalid_argument for bad
  /// options, BuildCancelled when `progress` returns false.
  Voxels(std::span<const Triangle> triangles, const VoxelOptions& opts = {}, const ProgressCallback& progress = {});

  std::string name() const override { return "voxels"; }
  /// Voxel hits, see the file comment. QueryOptions do not apply (the march
  /// is always front to back; no triangle is tested). RayStats:
  /// nodes_visited = octree steps (octants entered, the hit included),
  /// empty_cells = empty octants skipped, box_tests = 1 (the domain).
  /// VisitTrace: node_entered per interior octant (id = node index) and a
  /// prim_hit with the voxel index.
  Hit closest_hit(const Ray& ray, const QueryOptions& opts, RayStats* stats = nullptr,
                  VisitTrace* trace = nullptr) const override;
  bool any_hit(const Ray& ray, const QueryOptions& opts, RayStats* stats = nullptr) const override;
  /// node_count (interior nodes stored), leaf_count (full octants, collapsed
  /// blocks included), max_depth = level, memory_bytes (the nodes); extra:
  /// "occupied_voxels", "dense_bytes" (a bit per voxel at this resolution),
  /// "level", "resolution", "voxel_size", "full_blocks" (collapsed blocks
  /// larger than one voxel).
  const BuildStats& build_stats() const override { return stats_; }

  const VoxelDomain& domain() const { return domain_; }
  std::span<const VoxelNode> nodes() const { return nodes_; }
  /// The root: nothing occupied (no nodes), everything occupied (no nodes),
  /// or nodes().back().
  enum class Root { empty, full, interior };
  Root root() const { return root_; }

  bool occupied(std::uint32_t x, std::uint32_t y, std::uint32_t z) const;
  /// Occupancy of the voxel containing p (false outside the domain).
  bool occupied_at(const glm::vec3& p) const;
  std::uint64_t occupied_count() const { return occupied_; }
  /// The same occupancy as a dense bit grid.
  DenseVoxelGrid to_dense() const;

 private:
  // Closest and any hit are the same march: the first occupied voxel.
  template <bool kCollect>
  Hit traverse(const Ray& ray, RayStats* stats, VisitTrace* trace) const;

  VoxelDomain domain_;
  std::vector<VoxelNode> nodes_;
  Root root_ = Root::empty;
  std::uint64_t occupied_ = 0;
  BuildStats stats_;
};

}  // namespace accelviz
