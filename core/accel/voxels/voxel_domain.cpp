#include "core/accel/voxels/voxel_domain.h"

#include "core/accel/kdtree/spatial_traversal.h"

#include <stdexcept>
#include <string>

namespace accelviz {

VoxelDomain make_voxel_domain(std::span<const Triangle> triangles, int level) {
  if (level < 0 || level > kVoxelMaxLevel)
    throw std::invalid_argument("voxels: level must lie in 0.." + std::to_string(kVoxelMaxLevel) + ", got " +
                                std::to_string(level));
  Aabb bounds;
  for (const Triangle& t : triangles)
    if (is_finite_triangle(t)) bounds.extend(t.bounds());
  VoxelDomain d;
  d.level = level;
  d.resolution = 1u << level;
  if (bounds.is_empty()) return d;  // unit cube at the origin, nothing occupied

  const glm::vec3 ext = bounds.extent();
  const glm::vec3 mag = glm::max(glm::abs(bounds.lo), glm::abs(bounds.hi));
  float side = std::max({ext.x, ext.y, ext.z}) * (1.0f + 1e-6f);
  side = std::max(side, 1e-6f * std::max({mag.x, mag.y, mag.z, 1e-30f}));
  d.lo = bounds.lo;
  d.voxel_size = side / static_cast<float>(d.resolution);
  // The last plane, computed by plane(), must not fall short of the bounds.
  for (int a = 0; a < 3; ++a)
    while (d.plane(a, d.resolution) < bounds.hi[a]) d.voxel_size = std::nextafter(d.voxel_size, kInfinity);
  const Aabb box = d.box();
  d.pad = spatial::cell_padding(box.lo, box.hi);
  return d;
}

}  // namespace accelviz
