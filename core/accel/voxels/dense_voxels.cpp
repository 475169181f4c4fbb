#include "core/accel/voxels/dense_voxels.h"

#include "core/accel/kdtree/spatial_traversal.h"

#include <bit>

namespace accelviz {

std::uint64_t DenseVoxelGrid::count() const {
  std::uint64_t n = 0;
  for (std::uint64_t w : bits) n += static_cast<std::uint64_t>(std::popcount(w));
  return n;
}

DenseVoxelGrid voxelize_dense(std::span<const Triangle> triangles, const VoxelDomain& d) {
  DenseVoxelGrid grid(d);
  const auto index_of = [&](float p, int a) -> std::int64_t {
    return static_cast<std::int64_t>(std::floor((p - d.lo[a]) / d.voxel_size));
  };
  for (const Triangle& tri : triangles) {
    if (!is_finite_triangle(tri)) continue;
    const Aabb b = padded_box(tri.bounds(), d.pad);
    std::uint32_t lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
      // One voxel of slack each side against the rounding of the floor; the
      // overlap predicate decides.
      const std::int64_t l = index_of(b.lo[a], a) - 1, h = index_of(b.hi[a], a) + 1;
      lo[a] = static_cast<std::uint32_t>(std::clamp<std::int64_t>(l, 0, d.resolution - 1));
      hi[a] = static_cast<std::uint32_t>(std::clamp<std::int64_t>(h, 0, d.resolution - 1));
    }
    for (std::uint32_t z = lo[2]; z <= hi[2]; ++z)
      for (std::uint32_t y = lo[1]; y <= hi[1]; ++y)
        for (std::uint32_t x = lo[0]; x <= hi[0]; ++x)
          if (!grid.get(x, y, z) && voxel_overlap(tri, d.voxel_box(x, y, z), d.pad)) grid.set(x, y, z);
  }
  return grid;
}

namespace {

// Start index on one axis: the number of interior planes 1..R-1 the ray has
// crossed strictly before t0 (ascending for a positive direction,
// descending for a negative one); for a ray parallel to the axis, the number
// of planes at or below the origin. Binary search: crossings are monotone in
// the plane index. This is the decision the sparse traversal makes level by
// level (spatial::split_at_plane with zero slack).
std::uint32_t start_index(const VoxelDomain& d, const Ray& r, int a, float t0) {
  const std::uint32_t R = d.resolution;
  const float o = r.origin[a], inv = r.inv_dir[a];
  const auto count = [&](auto&& pred) {  // number of i in [1, R-1] with pred(i), pred monotone true..false
    std::uint32_t lo = 1, hi = R;        // answer + 1 lies in [lo, hi]
    while (lo < hi) {
      const std::uint32_t mid = (lo + hi) / 2;
      if (pred(mid)) lo = mid + 1;
      else hi = mid;
    }
    return lo - 1;
  };
  if (std::isinf(inv)) return count([&](std::uint32_t i) { return d.plane(a, i) <= o; });
  if (inv > 0.0f) return count([&](std::uint32_t i) { return (d.plane(a, i) - o) * inv < t0; });
  // Negative direction: plane i is crossed (ts < t0) for the top planes; the
  // predicate "not crossed" holds for i = 1..k.
  const std::uint32_t not_crossed = count([&](std::uint32_t i) { return !((d.plane(a, i) - o) * inv < t0); });
  return not_crossed;
}

}  // namespace

Hit dense_voxel_march(const DenseVoxelGrid& grid, const Ray& ray, RayStats* stats) {
  Hit hit;
  const VoxelDomain& d = grid.domain;
  VoxelSegment seg;
  if (!spatial::is_traversable(ray) || !voxel_segment(d, ray, seg)) return hit;

  std::int64_t idx[3];
  int step[3];
  float t_next[3];
  float line_t = -kInfinity;  // where the ray's line enters the current voxel
  int line_axis = -1;
  for (int a = 0; a < 3; ++a) {
    idx[a] = start_index(d, ray, a, seg.t0);
    if (std::isinf(ray.inv_dir[a])) {
      step[a] = 0;
      t_next[a] = kInfinity;
      continue;
    }
    step[a] = ray.inv_dir[a] > 0.0f ? 1 : -1;
    const std::uint32_t i = static_cast<std::uint32_t>(idx[a]);
    const float near_plane = d.plane(a, step[a] > 0 ? i : i + 1);
    const float far_plane = d.plane(a, step[a] > 0 ? i + 1 : i);
    const float tn = (near_plane - ray.origin[a]) * ray.inv_dir[a];
    if (tn >= line_t) line_t = tn, line_axis = a;  // equal t: the higher axis is crossed later
    t_next[a] = (far_plane - ray.origin[a]) * ray.inv_dir[a];
  }

  for (;;) {
    const bool occupied =
        grid.get(static_cast<std::uint32_t>(idx[0]), static_cast<std::uint32_t>(idx[1]), static_cast<std::uint32_t>(idx[2]));
    if (stats) {
      ++stats->nodes_visited;
      if (!occupied) ++stats->empty_cells;
    }
    if (occupied) {
      hit.t = std::max(seg.t0, line_t);
      hit.ng = voxel_face_normal(ray, line_axis);
      hit.prim = d.linear(static_cast<std::uint32_t>(idx[0]), static_cast<std::uint32_t>(idx[1]),
                          static_cast<std::uint32_t>(idx[2]));
      return hit;
    }
    const int a = t_next[0] <= t_next[1] ? (t_next[0] <= t_next[2] ? 0 : 2) : (t_next[1] <= t_next[2] ? 1 : 2);
    if (!(t_next[a] <= seg.t1) || step[a] == 0) return hit;
    idx[a] += step[a];
    if (idx[a] < 0 || idx[a] >= static_cast<std::int64_t>(d.resolution)) return hit;
    line_t = t_next[a];
    line_axis = a;
    t_next[a] = (d.plane(a, static_cast<std::uint32_t>(step[a] > 0 ? idx[a] + 1 : idx[a])) - ray.origin[a]) * ray.inv_dir[a];
  }
}

}  // namespace accelviz
