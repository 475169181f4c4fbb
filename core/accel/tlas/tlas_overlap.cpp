// Instance overlap (see tlas_overlap.h).
#include "core/accel/tlas/tlas_overlap.h"

#include "core/accel/tlas/tlas.h"

#include <algorithm>
#include <vector>

namespace accelviz {

namespace {

double volume_of(const Aabb& b) {
  const glm::dvec3 e = glm::max(glm::dvec3(b.hi) - glm::dvec3(b.lo), glm::dvec3(0.0));
  return e.x * e.y * e.z;
}

double area_of(const Aabb& b) {
  const glm::dvec3 e = glm::max(glm::dvec3(b.hi) - glm::dvec3(b.lo), glm::dvec3(0.0));
  return 2.0 * (e.x * e.y + e.y * e.z + e.z * e.x);
}

}  // namespace

InstanceOverlap instance_overlap(std::span<const Aabb> boxes) {
  InstanceOverlap out;
  std::vector<Aabb> live;
  live.reserve(boxes.size());
  Aabb root;
  for (const Aabb& b : boxes)
    if (!b.is_empty()) {
      live.push_back(b);
      root.extend(b);
    }
  out.instances = live.size();
  if (live.empty()) return out;
  out.root_area = area_of(root);
  out.root_volume = volume_of(root);
  std::sort(live.begin(), live.end(), [](const Aabb& a, const Aabb& b) { return a.lo.x < b.lo.x; });
  for (std::size_t i = 0; i < live.size(); ++i)
    for (std::size_t j = i + 1; j < live.size() && live[j].lo.x <= live[i].hi.x; ++j) {
      const Aabb c = Aabb::intersection(live[i], live[j]);
      if (c.lo.x > c.hi.x || c.lo.y > c.hi.y || c.lo.z > c.hi.z) continue;
      const double a = area_of(c);
      if (a <= 0.0) continue;  // touching along an edge or at a corner only
      ++out.overlapping_pairs;
      out.area_sum += a;
      out.volume_sum += volume_of(c);
    }
  if (out.root_area > 0.0) out.area_ratio = out.area_sum / out.root_area;
  if (out.root_volume > 0.0) out.volume_ratio = out.volume_sum / out.root_volume;
  return out;
}

InstanceOverlap instance_overlap(const Tlas& tlas) {
  std::vector<Aabb> boxes;
  boxes.reserve(tlas.instances().size());
  for (const TlasInstance& inst : tlas.instances()) boxes.push_back(inst.world_bounds);
  return instance_overlap(boxes);
}

}  // namespace accelviz
