#pragma once
// The dense reference for the sparse voxel octree: one bit per voxel, filled
// triangle by triangle with the same occupancy predicate, and marched with a
// plain 3D-DDA (Amanatides & Woo 1987). Its answers define what the sparse
// structure must return, so it is written for clarity, not speed.
#include "core/accel/accel.h"
#include "core/accel/voxels/voxel_domain.h"

#include <cstdint>
#include <span>
#include <vector>

namespace accelviz {

/// Occupancy of every voxel of a domain, one bit each (x fastest).
struct DenseVoxelGrid {
  VoxelDomain domain;
  std::vector<std::uint64_t> bits;

  explicit DenseVoxelGrid(const VoxelDomain& d)
      : domain(d), bits((static_cast<std::uint64_t>(d.resolution) * d.resolution * d.resolution + 63) / 64, 0) {}

  bool get(std::uint32_t x, std::uint32_t y, std::uint32_t z) const {
    const std::uint64_t i = index(x, y, z);
    return (bits[i >> 6] >> (i & 63)) & 1u;
  }
  void set(std::uint32_t x, std::uint32_t y, std::uint32_t z) {
    const std::uint64_t i = index(x, y, z);
    bits[i >> 6] |= std::uint64_t{1} << (i & 63);
  }
  /// Number of occupied voxels.
  std::uint64_t count() const;
  /// Bytes of the bit array (the "dense_bytes" the sparse octree is compared with).
  std::uint64_t bytes() const { return bits.size() * sizeof(std::uint64_t); }

 private:
  std::uint64_t index(std::uint32_t x, std::uint32_t y, std::uint32_t z) const {
    return x + static_cast<std::uint64_t>(domain.resolution) * (y + static_cast<std::uint64_t>(domain.resolution) * z);
  }
};

/// Brute-force voxelization: for every finite triangle, every voxel near its
/// bounds that voxel_overlap() accepts. Independent of the sparse builder
/// (which filters top-down), so the two can be checked against each other.
DenseVoxelGrid voxelize_dense(std::span<const Triangle> triangles, const VoxelDomain& domain);

/// First occupied voxel along [ray.tmin, ray.tmax] by a voxel-by-voxel
/// 3D-DDA. The start voxel is chosen by comparing plane crossings with the
/// segment's start (not by flooring a rounded position), and every boundary
/// distance is (plane - origin) · inv_dir, so the march sees exactly the
/// voxels and distances the sparse octree's traversal sees.
/// Hit: t = max(tmin, t where the ray's line enters the voxel), ng = that
/// face's normal against the ray, prim = domain.linear(x, y, z); u = v = 0.
/// stats (optional): nodes_visited = voxels stepped, empty_cells = empty ones.
Hit dense_voxel_march(const DenseVoxelGrid& grid, const Ray& ray, RayStats* stats = nullptr);

}  // namespace accelviz
