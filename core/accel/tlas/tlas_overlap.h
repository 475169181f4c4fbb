#pragma once
// Instance overlap of a two-level structure: how much the instances' world
// boxes overlap one another. A ray inside an overlap region must enter every
// instance whose box covers it, so overlap is what makes a TLAS expensive
// even when the TLAS itself is tight. Defined over the instances' world
// boxes (Tlas::instances()[i].world_bounds), pairwise:
//   area_ratio   = sum over pairs i < j of SA(B_i ∩ B_j) / SA(union box)
//   volume_ratio = sum over pairs i < j of Vol(B_i ∩ B_j) / Vol(union box)
// where the union box is the box of all instance boxes (the TLAS root).
// area_ratio is the expected number of extra instance entries per ray that
// reaches the root, under the SAH's uniform-ray assumption (an upper bound
// of the overlap's cost: pairs count once each). 0 for disjoint instances.
#include <cstdint>
#include <span>

#include "core/math/aabb.h"

namespace accelviz {

struct InstanceOverlap {
  std::uint64_t instances = 0;
  std::uint64_t overlapping_pairs = 0;  ///< pairs whose boxes share a region of positive volume or area
  double area_sum = 0.0;                ///< sum of pairwise intersection surface areas
  double volume_sum = 0.0;              ///< sum of pairwise intersection volumes
  double root_area = 0.0;               ///< surface area of the union box
  double root_volume = 0.0;             ///< volume of the union box
  double area_ratio = 0.0;              ///< area_sum / root_area (0 when root_area is 0)
  double volume_ratio = 0.0;            ///< volume_sum / root_volume (0 when root_volume is 0)
};

/// Pairwise overlap of BOXES (empty boxes are skipped). Sweep along x:
/// O(n log n + pairs whose x-extents overlap).
InstanceOverlap instance_overlap(std::span<const Aabb> boxes);

class Tlas;
/// The overlap of TLAS's instances as they stand now (their world boxes):
/// what SceneAnimator::step measures per frame (FrameStats::overlap).
InstanceOverlap instance_overlap(const Tlas& tlas);

}  // namespace accelviz
