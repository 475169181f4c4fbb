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

/// The reference's answer for one ray over `tris`, computed once, judging any number of answers.
class Referee {
 public:
  Referee(std::span<const Triangle> tris, const Ray& ray)
      : tris_(tris), ray_(ray), ref_(ReferenceTracer(tris).closest_hit(ray)) {}

  /// True when the reference judges `closest` and `any` (a structure's answers for the ray) a
  /// match or a near tie (classify_closest, classify_any).
  bool accepts(const Hit& closest, bool any) const {
    const Verdict vc = classify_closest(tris_, ray_, ref_, closest);
    const Verdict va = classify_any(ref_, any);
    return (vc == Verdict::match || vc == Verdict::near_tie) && (va == Verdict::match || va == Verdict::near_tie);
  }

 private:
  std::span<const Triangle> tris_;
  Ray ray_;
  ReferenceHit ref_;
};

/// Referee(tris, ray).accepts(closest, any): for a ray with one answer to judge.
inline bool reference_accepts(std::span<const Triangle> tris, const Ray& ray, const Hit& closest, bool any) {
  return Referee(tris, ray).accepts(closest, any);
}

}  // namespace accelviz::test_referee
