#pragma once
// The double-precision reference as the referee of a float answer that differs from a float brute
// force: the judgement `accelviz verify` makes (core/accel/reference.h, docs/robustness.md). A
// Moller-Trumbore "hit" can lie outside its triangle, or at a t off by more than the tests'
// 1e-6, where the ray grazes the triangle or meets it at a vertex; the structure, whose boxes
// hold only the triangle itself, then rightly answers another triangle, which the reference
// confirms as a match or a tie within rounding.
#include <span>

#include "core/accel/reference.h"

namespace accelviz::test_referee {

/// True when the reference judges `closest` and `any` (a structure's answers for `ray` over
/// `tris`) a match or a near tie (classify_closest, classify_any).
inline bool reference_accepts(std::span<const Triangle> tris, const Ray& ray, const Hit& closest, bool any) {
  const ReferenceHit ref = ReferenceTracer(tris).closest_hit(ray);
  const Verdict vc = classify_closest(tris, ray, ref, closest);
  const Verdict va = classify_any(ref, any);
  return (vc == Verdict::match || vc == Verdict::near_tie) && (va == Verdict::match || va == Verdict::near_tie);
}

}  // namespace accelviz::test_referee
