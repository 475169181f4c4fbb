#pragma once
// The robustness lab (issue 9): for a scene, adversarial ray sets (through
// vertices, through shared edges, axis-aligned with +0/-0 components, grazing
// a triangle's plane) traced with the fast and the robust variants of the two
// float tests every traversal depends on:
//   triangle test: Moller-Trumbore (fast) vs watertight (robust),
//   slab test:     plain (fast)  vs padded by 1+2γ(3) (robust),
// each compared with the double-precision reference per ray, with the time
// each variant costs. The four combinations run one and the same BVH
// traversal (over the nodes of a Bvh built with default options) so that only
// the tests differ; optionally a structure's own traversal is timed and
// checked too, with both triangle tests (its slab test is its own); Embree,
// which ignores our triangle test, in its default and its robust mode.
//
// Per ray and variant:
//   miss        the variant finds nothing at the reference's closest surface
//               point (no hit, or only a farther one): the ray leaks through
//               a hole. Counted where the reference's closest point is a
//               clear hit or the ray goes on to hit something clearly (it
//               entered the surface); a silhouette graze with nothing clear
//               behind is a rounding decision and not counted;
//   double hit  the variant reports two or more triangles at the closest
//               surface point (within the reference's t tolerance) where the
//               reference finds exactly one: a shared edge counted twice;
//   wrong       the variant's closest hit is another primitive or t than the
//               reference's, not explained by rounding (classify_closest).
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "core/accel/accel.h"

namespace accelviz {

/// The adversarial ray families, in the order reports list them.
enum class LabFamily : std::uint8_t { vertex, edge, axis, grazing };
inline constexpr int kLabFamilies = 4;
const char* to_string(LabFamily f);

struct LabRay {
  Ray ray;
  LabFamily family;
};

/// `count` rays spread evenly over the four families, deterministic in
/// `seed`: vertex (from outside the bounds exactly at a triangle vertex),
/// edge (at a point of a triangle edge, midpoints included), axis (along
/// ±x/±y/±z through a vertex or edge point, the other components +0 or -0),
/// grazing (in a triangle's plane through its interior).
std::vector<LabRay> lab_rays(std::span<const Triangle> triangles, std::size_t count, std::uint64_t seed);

struct LabOptions {
  std::size_t rays = 20000;
  std::uint64_t seed = 1;
  std::string structure;  ///< "" or a factory name (not voxels): also time its own traversal (embree: both modes)
  unsigned threads = 0;   ///< 0: all hardware threads (timing runs on one thread)
};

/// Figures of one variant.
struct LabVariant {
  std::string name;  ///< "moller-trumbore + plain slab", ..., "kdtree (watertight)"
  TriangleTest triangle_test = TriangleTest::watertight;
  bool padded_slab = true;
  bool own_structure = false;  ///< a structure's own traversal (double hits come from the lab BVH)
  /// Embree's rows: "default" or "robust" (RTC_SCENE_FLAG_ROBUST), its own
  /// modes; Embree ignores our triangle test, so triangle_test does not apply.
  /// Empty for every other variant.
  std::string embree_mode;
  /// False for Embree's rows: it reports one hit per ray, and the lab BVH's
  /// count with our triangle test would say nothing about Embree.
  bool double_hits_counted = true;
  std::uint64_t misses = 0;
  std::uint64_t double_hits = 0;
  std::uint64_t wrong = 0;
  std::uint64_t not_traced = 0;  ///< rays the structure refuses (Embree's limits): neither traced nor classified
  std::uint64_t misses_by_family[kLabFamilies] = {};
  std::uint64_t double_hits_by_family[kLabFamilies] = {};
  double ms = 0.0;  ///< closest-hit tracing of every ray, one thread
  double mrays_per_s = 0.0;
  /// Per ray: 0 ok, 1 miss, 2 double hit, 3 wrong (miss wins over double hit), 4 not traced.
  std::vector<std::uint8_t> per_ray;
};

struct LabResult {
  std::size_t triangles = 0;
  std::size_t rays = 0;
  std::uint64_t reference_hits = 0;
  std::uint64_t rays_by_family[kLabFamilies] = {};
  std::vector<LabRay> lab_rays;
  std::vector<LabVariant> variants;
  double reference_ms = 0.0;
  /// The structure's build refused the scene (Embree: a vertex beyond its
  /// range): its words, and no variant of it; the lab's own variants still run.
  std::string structure_refused;
  /// Rays the structure refuses (Accelerator::ray_problem, Embree's limits):
  /// how many, the first and why. Its variants trace the others.
  std::uint64_t structure_rays_refused = 0;
  std::size_t structure_first_refused_ray = 0;
  std::string structure_refused_ray_reason;
};

/// Runs the lab. A structure that refuses the scene or rays (Embree) does not
/// stop it: see LabResult::structure_refused. Throws std::invalid_argument for
/// an unknown or voxel structure, BuildCancelled when `keep_going` returns false (checked between
/// stages and every few thousand rays).
LabResult run_robustness_lab(std::span<const Triangle> triangles, const LabOptions& opts,
                             const std::function<bool()>& keep_going = {});

}  // namespace accelviz
