#pragma once
// The cubic domain of a voxelization and the definitions that the sparse
// voxel octree and its dense reference share, so that both agree bit for bit:
// which voxels are occupied, where each voxel's planes lie, and how a ray's
// segment through the domain starts.
#include "core/geometry/tri_box_overlap.h"
#include "core/geometry/triangle.h"
#include "core/math/aabb.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>

namespace accelviz {

/// Deepest voxelization level (2^10 = 1024 voxels per axis).
inline constexpr int kVoxelMaxLevel = 10;

/// A cube of 2^level voxels per axis. Every plane is computed by the one
/// expression plane(axis, i) = lo + i·voxel_size, in float, by everyone.
struct VoxelDomain {
  glm::vec3 lo{0.0f};
  float voxel_size = 1.0f;
  int level = 0;
  std::uint32_t resolution = 1;  ///< 2^level
  float pad = 0.0f;              ///< voxel boxes are grown by this before the overlap test

  float plane(int axis, std::uint32_t i) const { return lo[axis] + static_cast<float>(i) * voxel_size; }
  Aabb box() const { return block_box(0, 0, 0, resolution); }
  /// Box of the size³ block of voxels whose lowest voxel is (x, y, z).
  Aabb block_box(std::uint32_t x, std::uint32_t y, std::uint32_t z, std::uint32_t size) const {
    return {{plane(0, x), plane(1, y), plane(2, z)}, {plane(0, x + size), plane(1, y + size), plane(2, z + size)}};
  }
  Aabb voxel_box(std::uint32_t x, std::uint32_t y, std::uint32_t z) const { return block_box(x, y, z, 1); }
  /// The linear voxel index reported as Hit::prim by voxel queries.
  std::uint32_t linear(std::uint32_t x, std::uint32_t y, std::uint32_t z) const {
    return x + resolution * (y + resolution * z);
  }
  /// Voxel containing p (by floor of the scaled offset, clamped to the
  /// domain); false when p lies outside the domain's box.
  bool voxel_of(const glm::vec3& p, std::uint32_t out[3]) const {
    if (!box().contains(p)) return false;
    for (int a = 0; a < 3; ++a) {
      const float x = (p[a] - lo[a]) / voxel_size;
      out[a] = x >= static_cast<float>(resolution) ? resolution - 1 : static_cast<std::uint32_t>(std::max(x, 0.0f));
    }
    return true;
  }
};

/// The domain of `triangles` at `level`: a cube whose side is a hair above
/// the largest extent of the finite triangles' bounds, anchored at their
/// lower corner (a flat scene then lies on a domain face rather than on a
/// voxel plane, where it would occupy two layers). Throws
/// std::invalid_argument when level is outside 0..kVoxelMaxLevel.
VoxelDomain make_voxel_domain(std::span<const Triangle> triangles, int level);

/// What "occupied" means: the voxel (or block) box grown by `pad` touches the
/// triangle. The bounds pre-check is part of the definition so that every
/// user evaluates exactly the same predicate.
inline bool voxel_overlap(const Triangle& tri, const Aabb& box, float pad) {
  const Aabb b = padded_box(box, pad);
  const Aabb tb = tri.bounds();
  if (tb.lo.x > b.hi.x || tb.hi.x < b.lo.x || tb.lo.y > b.hi.y || tb.hi.y < b.lo.y || tb.lo.z > b.hi.z ||
      tb.hi.z < b.lo.z)
    return false;
  return triangle_box_overlap(tri, b);
}

/// A ray's segment through the domain: [t0, t1], and where its line enters
/// the domain box (line_t, before clipping to tmin) through which axis'
/// face (-1 when no axis is crossed: a zero direction). Crossings at equal t
/// count as ordered by axis (x, y, z), as the dense march steps them, so the
/// entry face at a tie is the highest axis.
struct VoxelSegment {
  float t0, t1;
  float line_t;
  int axis;
};

/// Clips the ray to the domain box (slab test without padding; a ray parallel
/// to an axis is inside that slab when its origin lies on or between the
/// planes). Returns false when the segment is empty.
inline bool voxel_segment(const VoxelDomain& d, const Ray& r, VoxelSegment& s) {
  s = {r.tmin, r.tmax, -kInfinity, -1};
  for (int a = 0; a < 3; ++a) {
    const float lo = d.plane(a, 0), hi = d.plane(a, d.resolution);
    if (std::isinf(r.inv_dir[a])) {
      if (r.origin[a] < lo || r.origin[a] > hi) return false;
      continue;
    }
    const bool neg = r.inv_dir[a] < 0.0f;
    const float tn = ((neg ? hi : lo) - r.origin[a]) * r.inv_dir[a];
    const float tf = ((neg ? lo : hi) - r.origin[a]) * r.inv_dir[a];
    if (tn >= s.line_t) s.line_t = tn, s.axis = a;  // at equal t the higher axis is the later crossing
    s.t0 = std::max(s.t0, tn);
    s.t1 = std::min(s.t1, tf);
  }
  return s.t0 <= s.t1;
}

/// The voxel hit normal: the face through which the ray's line enters the
/// voxel (axis `axis`), facing against the ray; zero without an axis.
inline glm::vec3 voxel_face_normal(const Ray& r, int axis) {
  glm::vec3 n(0.0f);
  if (axis >= 0) n[axis] = r.direction[axis] > 0.0f ? -1.0f : 1.0f;
  return n;
}

}  // namespace accelviz
