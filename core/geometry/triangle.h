#pragma once
// Ray-triangle intersection: watertight (default) and Moller-Trumbore (fast).
#include <cmath>
#include <glm/glm.hpp>
#include <type_traits>

#include "core/geometry/hit.h"
#include "core/math/aabb.h"

namespace accelviz {

struct Triangle {
  glm::vec3 v0, v1, v2;

  Aabb bounds() const {
    Aabb b = Aabb::of_point(v0);
    b.extend(v1);
    b.extend(v2);
    return b;
  }
  glm::vec3 centroid() const { return (v0 + v1 + v2) * (1.0f / 3.0f); }
  /// Unnormalised geometric normal (v1-v0)x(v2-v0); zero for a degenerate triangle.
  glm::vec3 cross_normal() const { return glm::cross(v1 - v0, v2 - v0); }
  float area() const { return 0.5f * glm::length(cross_normal()); }
};

/// Which ray-triangle test a query uses. Selectable at run time so that the
/// cost of accuracy can be measured (see docs/accuracy-vs-time.md).
enum class TriangleTest {
  watertight,       ///< Woop, Benthin, Wald, "Watertight Ray/Triangle Intersection", JCGT 2013
  moller_trumbore,  ///< Moller & Trumbore 1997: fewer operations, may leak through shared edges
};

/// Per-ray constants of the watertight test: the axis permutation that makes
/// the ray's dominant axis z, and the shear that maps the ray onto +z.
struct WatertightRay {
  int kx = 0, ky = 1, kz = 2;
  float sx = 0.0f, sy = 0.0f, sz = 1.0f;

  WatertightRay() = default;
  explicit WatertightRay(const glm::vec3& dir);
};

/// The axis that the watertight set-up makes z, from |d.x|, |d.y|, |d.z|: the
/// largest, the first of equal maxima (x over y, and x or y over z only when
/// strictly larger), by selections without branches, into z. F is float
/// (Z int), or a GCC vector of floats for the packet walk's lanes (Z the
/// matching int vector): one source for both, so every lane picks the axes
/// its single ray would. (References, not values: a 32-byte vector passed by
/// value in SSE-only code draws GCC's -Wpsabi warning.)
template <class F, class Z>
[[gnu::always_inline]] inline void watertight_z_axis(const F& ax, const F& ay, const F& az, Z& z) {
  const F axy = ay < ax ? ax : ay;  // the larger of x and y (x only when strictly larger)
  Z kxy, xy_not_above_z;            // 1 where the comparison is false
  if constexpr (std::is_same_v<F, float>) {
    kxy = static_cast<int>(!(ax > ay));
    xy_not_above_z = static_cast<int>(!(axy > az));
  } else {  // vector comparisons give -1 (true) or 0 per lane
    kxy = (ax > ay) + 1;
    xy_not_above_z = (axy > az) + 1;
  }
  z = kxy + (2 - kxy) * xy_not_above_z;
}

/// The axes that become x and y for z (before the winding swap): (z + 1) % 3
/// and (z + 2) % 3, from 2-bit tables (0->1, 1->2, 2->0 and 0->2, 1->0, 2->1).
[[gnu::always_inline]] inline int watertight_x_axis(int z) {
  return (0x09 >> (2 * z)) & 3;
}
[[gnu::always_inline]] inline int watertight_y_axis(int z) {
  return (0x12 >> (2 * z)) & 3;
}

// Inline and free of data-dependent branches: rays of a diffuse bounce pick
// their dominant axis and its sign at random, and the branchy form (glm::abs
// and nested selections) mispredicted several times per ray on every
// traversal's set-up. The selections below compile to conditional moves; the
// axes, signs and quotients are those of the nested form (std::fabs and
// glm::abs order the same values; the divisions take the same operands).
inline WatertightRay::WatertightRay(const glm::vec3& dir) {
  const float* d = &dir.x;
  int z;
  watertight_z_axis(std::fabs(d[0]), std::fabs(d[1]), std::fabs(d[2]), z);
  // Keep the winding: swap x/y when dir[kz] < 0.
  const int x = watertight_x_axis(z), y = watertight_y_axis(z);
  const float dz = d[z];
  const int swap = -static_cast<int>(dz < 0.0f);  // all ones or zero
  kz = z;
  kx = x ^ ((x ^ y) & swap);
  ky = y ^ ((x ^ y) & swap);
  sx = d[kx] / dz;
  sy = d[ky] / dz;
  sz = 1.0f / dz;
}

/// Watertight test. Accepts t in [tmin, tmax]; on a hit fills t, u, v of
/// `hit` (not prim or ng) and returns true. Edge functions that round to
/// exactly zero are recomputed in double precision, as the paper prescribes,
/// so that a ray through a shared edge or vertex hits at least one triangle.
bool intersect_watertight(const Ray& ray, const WatertightRay& wr, const Triangle& tri, float tmin, float tmax,
                          Hit& hit);

/// Moller-Trumbore test, no epsilon beyond det == 0. Same contract.
bool intersect_moller_trumbore(const Ray& ray, const Triangle& tri, float tmin, float tmax, Hit& hit);

/// Geometric unit normal of a triangle (zero vector for a degenerate one).
glm::vec3 triangle_normal(const Triangle& tri);

/// Dispatch on the run-time choice; traversals hoist this out of their loops.
inline bool intersect_triangle(TriangleTest test, const Ray& ray, const WatertightRay& wr, const Triangle& tri,
                               float tmin, float tmax, Hit& hit) {
  return test == TriangleTest::watertight ? intersect_watertight(ray, wr, tri, tmin, tmax, hit)
                                          : intersect_moller_trumbore(ray, tri, tmin, tmax, hit);
}

}  // namespace accelviz
