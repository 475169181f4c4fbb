#pragma once
// Ray-triangle intersection: watertight (default) and Moller-Trumbore (fast).
#include "core/geometry/hit.h"
#include "core/math/aabb.h"

#include <glm/glm.hpp>

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
