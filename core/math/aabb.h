#pragma once
// Axis-aligned bounding boxes and the robust ray-slab test.
#include "core/math/ray.h"

#include <glm/glm.hpp>

#include <algorithm>

namespace accelviz {

struct Aabb {
  glm::vec3 lo{kInfinity};
  glm::vec3 hi{-kInfinity};

  static Aabb empty() { return {}; }
  static Aabb of_point(const glm::vec3& p) { return {p, p}; }

  bool is_empty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
  void extend(const glm::vec3& p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  void extend(const Aabb& b) {
    lo = glm::min(lo, b.lo);
    hi = glm::max(hi, b.hi);
  }
  glm::vec3 extent() const { return hi - lo; }
  glm::vec3 center() const { return 0.5f * (lo + hi); }
  /// Surface area; 0 for an empty box (so SAH terms of empty children vanish).
  float surface_area() const {
    if (is_empty()) return 0.0f;
    const glm::vec3 e = extent();
    return 2.0f * (e.x * e.y + e.y * e.z + e.z * e.x);
  }
  /// Half the surface area: enough for SAH ratios, one multiply cheaper.
  float half_area() const {
    if (is_empty()) return 0.0f;
    const glm::vec3 e = extent();
    return e.x * e.y + e.y * e.z + e.z * e.x;
  }
  int largest_axis() const {
    const glm::vec3 e = extent();
    return (e.x >= e.y && e.x >= e.z) ? 0 : (e.y >= e.z ? 1 : 2);
  }
  bool contains(const Aabb& b) const {
    return glm::all(glm::lessThanEqual(lo, b.lo)) && glm::all(glm::greaterThanEqual(hi, b.hi));
  }
  bool contains(const glm::vec3& p) const {
    return glm::all(glm::lessThanEqual(lo, p)) && glm::all(glm::lessThanEqual(p, hi));
  }
  static Aabb merge(const Aabb& a, const Aabb& b) {
    Aabb r = a;
    r.extend(b);
    return r;
  }
  static Aabb intersection(const Aabb& a, const Aabb& b) { return {glm::max(a.lo, b.lo), glm::min(a.hi, b.hi)}; }
};

/// Entry/exit distances of a ray through a box.
struct SlabInterval {
  float t_entry;
  float t_exit;
};

/// Robust ray/box slab test (Williams et al. 2005; Ize, "Robust BVH Ray
/// Traversal", JCGT 2013).
///  - The near plane of each slab is chosen by the sign of inv_dir (a -0
///    direction gives -inf and picks the upper plane as near), so the near and
///    far distances never need sorting.
///  - A +0 or -0 direction component gives inv_dir = ±inf. With the origin
///    strictly inside the slab the distances are -inf/+inf and the slab does
///    not restrict the ray; outside it, the near distance is +inf and the box
///    is missed. With the origin exactly on a slab plane, 0·inf is NaN: the
///    comparisons below are written so that a NaN leaves the interval as it
///    is, i.e. a ray lying in a face plane counts as touching the box.
///  - The far distance is scaled by 1+2γ(3) so that rounding never turns a
///    hit into a miss.
/// Returns true when [max(t_entry,tmin), min(t_exit,tmax)] is non-empty.
template <bool Padded = true>
inline bool intersect_slab(const Aabb& box, const glm::vec3& origin, const glm::vec3& inv_dir, float tmin,
                           float tmax, SlabInterval& out) {
  float t0 = tmin, t1 = tmax;
  for (int a = 0; a < 3; ++a) {
    const bool neg = inv_dir[a] < 0.0f;
    const float near_plane = neg ? box.hi[a] : box.lo[a];
    const float far_plane = neg ? box.lo[a] : box.hi[a];
    const float tn = (near_plane - origin[a]) * inv_dir[a];
    float tf = (far_plane - origin[a]) * inv_dir[a];
    if constexpr (Padded) tf *= kSlabExitScale;
    t0 = tn > t0 ? tn : t0;  // NaN: comparison false, t0 kept
    t1 = tf < t1 ? tf : t1;  // NaN: comparison false, t1 kept
  }
  out = {t0, t1};
  return t0 <= t1;
}

inline bool intersect_slab(const Aabb& box, const Ray& r, SlabInterval& out) {
  return intersect_slab(box, r.origin, r.inv_dir, r.tmin, r.tmax, out);
}

/// The unpadded ("plain") slab test, kept so that the robustness lab can show
/// what the padding buys. Same NaN handling, no conservative scaling.
inline bool intersect_slab_plain(const Aabb& box, const Ray& r, SlabInterval& out) {
  return intersect_slab<false>(box, r.origin, r.inv_dir, r.tmin, r.tmax, out);
}

}  // namespace accelviz
