#pragma once
// Differential verification of every structure against the double-precision
// reference (core/accel/reference.h) on random, adversarial and camera rays.
// The engine of `accelviz verify` and of the CI test at scale.
#include "core/accel/factory.h"
#include "core/accel/reference.h"

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace accelviz {

/// A structure to verify: the factory name plus, for "bvh", the splitter.
struct VerifyStructure {
  std::string label;  ///< as printed: "brute", "bvh-binned", "kdtree", ...
  std::string factory_name;
  StructureOptions options;
  /// Named in the list by itself ("embree"), not brought in by "all": the
  /// command treats a refusal of such a structure as an error (exit 1).
  bool named = false;
};

/// "all" or a comma list of brute, brute-bbox, bvh (every splitter),
/// bvh-binned, bvh-exact, bvh-median, bvh-lbvh, kdtree, grid, octree, tlas,
/// embree. Voxels are refused:
/// their hits are voxels, not triangles. Throws std::invalid_argument.
std::vector<VerifyStructure> parse_verify_structures(const std::string& list, unsigned threads);

/// The rays: a seeded, deterministic mix, whatever the thread count.
///  - 40% random: origins inside and around the bounds, random directions or
///    aimed at a random point of the bounds;
///  - 45% adversarial: aimed exactly at a triangle's vertex or at a point on
///    one of its edges; axis-aligned with +0/-0 in the other components;
///    grazing along a triangle's plane; origins on the bounds' faces and
///    mid-planes (where root splits and cell boundaries lie);
///  - 15% camera rays of the framing view at random image points.
std::vector<Ray> verify_rays(std::span<const Triangle> triangles, std::size_t count, std::uint64_t seed);

/// Counts for one structure.
struct VerifyCounts {
  std::uint64_t rays = 0;
  std::uint64_t mismatched_prim = 0;     ///< closest hit: other primitive / hit vs miss, not explained by rounding
  std::uint64_t t_beyond_tolerance = 0;  ///< closest hit: same primitive, t outside tolerance
  std::uint64_t anyhit_disagree = 0;     ///< any hit != reference validity, not explained by rounding
  std::uint64_t near_ties = 0;           ///< disagreements within rounding (closest and any hit)
  double build_ms = 0.0;

  bool ok() const { return mismatched_prim == 0 && t_beyond_tolerance == 0 && anyhit_disagree == 0; }
  VerifyCounts& operator+=(const VerifyCounts& o);
};

/// A structure that refused the scene or some rays (Embree's limits, see
/// EmbreeAccelerator::ray_problem): it is checked on the rays it takes, or
/// not at all when it refused the scene.
struct VerifyNotChecked {
  std::string label;
  bool named = false;           ///< VerifyStructure::named
  bool scene_refused = false;   ///< the build refused the scene: no ray was checked
  std::uint64_t rays = 0;       ///< rays not checked (every ray when scene_refused)
  std::uint64_t first_ray = 0;  ///< the first ray refused (when !scene_refused)
  std::string reason;           ///< the structure's words, without its "embree: " prefix
};

struct VerifyResult {
  std::uint64_t rays = 0;
  std::uint64_t reference_hits = 0;
  std::vector<std::pair<std::string, VerifyCounts>> per_structure;
  VerifyCounts total;  ///< sums over structures (rays = rays per structure)
  double reference_ms = 0.0;
  double total_ms = 0.0;
  /// A few failing rays (structure, ray index, what) for the report.
  std::vector<std::string> examples;
  /// Structures that refused the scene or some rays, in the list's order.
  std::vector<VerifyNotChecked> not_checked;

  /// No disagreement on any ray checked (a refusal is not a disagreement).
  bool ok() const { return total.ok(); }
  /// A structure named by itself refused the scene or a ray.
  bool named_refused() const {
    for (const VerifyNotChecked& n : not_checked)
      if (n.named) return true;
    return false;
  }
};

/// Traces `rays` on every structure in closest and any-hit mode and compares
/// with the reference, over `threads` threads (0: all). With `scene` (whose
/// flattened triangle list `triangles` must be), "tlas" builds its two levels
/// from the scene's meshes and instances and is compared with the brute force
/// over the flattened triangles; without it, "tlas" is one instance over
/// `triangles`. Throws std::invalid_argument when `scene`'s triangles are not
/// `triangles`. A structure whose build refuses the scene (Embree: a vertex
/// beyond its range) or that refuses rays (Accelerator::ray_problem) does not
/// stop the others: it is checked on the rays it takes and listed in
/// `not_checked`. `progress` hears the fraction of the rays traced (the reference's and every
/// structure's), from the tracing threads; it cannot cancel.
VerifyResult verify_structures(std::span<const Triangle> triangles, std::span<const Ray> rays,
                               const std::vector<VerifyStructure>& structures, unsigned threads,
                               const Scene* scene = nullptr, const ProgressCallback& progress = {});

}  // namespace accelviz
