#pragma once
// Double-precision brute-force reference for checking every structure (issue
// "Hard cases stay numerically stable"). The float vertices are taken as
// exact; the watertight test of Woop, Benthin & Wald (JCGT 2013) is then run
// entirely in double, so its answer is the float scene's "true" answer up to
// ~1e-16 relative, far below the float structures' own rounding.
//
// Where the true answer is decided by less than float rounding (a ray through
// an edge or vertex, a ray grazing a triangle's plane), a float structure may
// legitimately answer either way. The reference therefore also reports how
// close each decision was, and the classifier counts such disagreements as
// near ties instead of failures.
#include <cstdint>
#include <limits>
#include <span>

#include "core/accel/accel.h"

namespace accelviz {

/// One double-precision ray-triangle test result.
struct ReferenceTriangleHit {
  bool hit = false;        ///< inside (edge functions all >= 0 or all <= 0, det != 0) and t in range
  bool near_edge = false;  ///< some edge function lies within float rounding of zero
  bool near_miss = false;  ///< a miss, but only by float rounding (would be a hit with the edges widened)
  double t = std::numeric_limits<double>::infinity();
  double t_tolerance =
      0.0;  ///< how far a float test's t may lie from t: max(kTTolerance·max(1,|t|), rounding estimate)
};

/// Relative size of the float rounding the classifier forgives on edge
/// functions: the float watertight test computes each edge function from
/// sheared coordinates with a handful of roundings of 2^-24 each.
inline constexpr double kEdgeRoundingScale = 64.0 * 5.9604644775390625e-08;  // 64 * 2^-24

/// Relative t tolerance of the comparison: |t - t_ref| <= kTTolerance * max(1, |t|).
inline constexpr double kTTolerance = 1e-6;

/// The watertight test in double precision over the triangle's float vertices.
/// t is accepted in [tmin, tmax].
ReferenceTriangleHit intersect_reference(const Ray& ray, const Triangle& tri, double tmin, double tmax);

/// Closest hit of the reference, with what the classifier needs about the
/// decisions that were within float rounding.
struct ReferenceHit {
  std::uint32_t prim = kInvalidId;  ///< closest primitive (lowest id on an exact tie); kInvalidId = miss
  double t = std::numeric_limits<double>::infinity();
  double t_tolerance = 0.0;        ///< of the closest hit (see ReferenceTriangleHit)
  bool closest_near_edge = false;  ///< the closest hit lies within rounding of its triangle's edge
  bool robust_hit = false;         ///< some primitive is hit clearly (not near an edge)
  bool near_hit = false;           ///< some primitive is hit or missed only by rounding

  bool valid() const { return prim != kInvalidId; }
};

/// Folds primitive `id`'s reference result `h` (for `ray`) into `best`: the
/// closest hit (lowest id on an exact tie) and the rounding flags. Any order of
/// ids gives the same `best`.
void fold_reference_hit(ReferenceHit& best, const ReferenceTriangleHit& h, std::uint32_t id, const Ray& ray);

/// Brute force in double over a triangle list (which must outlive it).
class ReferenceTracer {
 public:
  explicit ReferenceTracer(std::span<const Triangle> triangles) : tris_(triangles) {}

  ReferenceHit closest_hit(const Ray& ray) const;
  /// True when anything lies in [ray.tmin, ray.tmax] (== closest_hit(ray).valid()).
  bool any_hit(const Ray& ray) const;

  std::span<const Triangle> triangles() const { return tris_; }

 private:
  std::span<const Triangle> tris_;
};

/// How a structure's closest hit compares with the reference.
enum class Verdict {
  match,     ///< same primitive at the same t (or both miss)
  near_tie,  ///< different answer, but the difference is within rounding (equal t, or an edge/vertex/grazing decision)
  mismatched_prim,     ///< a different primitive (or hit vs miss) that rounding does not explain
  t_beyond_tolerance,  ///< the same primitive at a t outside the tolerance
};

const char* to_string(Verdict v);

/// |a - b| <= max(tolerance, kTTolerance * max(1, |a|, |b|)).
bool same_t(double a, double b, double tolerance = 0.0);

/// Classifies a structure's closest hit `got` for `ray` against `ref`.
Verdict classify_closest(std::span<const Triangle> triangles, const Ray& ray, const ReferenceHit& ref, const Hit& got);

/// Any-hit answer: correct when it equals ref.valid(); a disagreement is a
/// near tie (returns near_tie) when the only hits are within rounding of an
/// edge, or the only near hits are misses by rounding; else mismatched_prim.
Verdict classify_any(const ReferenceHit& ref, bool got);

}  // namespace accelviz
