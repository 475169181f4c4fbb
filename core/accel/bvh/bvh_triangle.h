#pragma once
// Inline ray/triangle tests for the BVH traversals, bit for bit the results of
// core/geometry/triangle.cpp's intersect_watertight and
// intersect_moller_trumbore (the steps they share are in
// core/geometry/triangle_inline.h).
//
// Why: those functions live in another translation unit (a call per
// triangle, no inlining into the traversal loop), and the watertight test
// picks the sheared axes with glm's run-time vec3::operator[], which GLM
// 0.9.9 implements as a switch: six data-dependent selections per triangle.
// Here the per-ray axis permutation is applied once (origin components and
// the shear constants are permuted per ray), and the vertex components are
// read through a pointer, (&v.x)[k]. Only the common float path is inline;
// every rare case that triangle.cpp handles specially (overflow, an edge
// function that rounds to zero, tiny determinants or distances) calls
// intersect_watertight itself, which recomputes from scratch, so the result
// never depends on which path answered. tests/core/test_bvh_triangle.cpp
// checks the agreement on random and adversarial input.
#include <cmath>

#include "core/geometry/triangle.h"
#include "core/geometry/triangle_inline.h"

namespace accelviz::bvh_detail {

/// Storage for a T that is left unset until assigned (a union with an empty
/// constructor skips T's default member initialisers): the walks' per-ray
/// triangle constants are assigned at the ray's first leaf, and many rays
/// never reach one. T must be trivially copyable and destructible.
template <class T>
union Unset {
  Unset() {}
  T v;
};

/// Per-ray constants of the inline watertight test.
struct InlineWatertightRay {
  WatertightRay wr;
  float ox = 0.0f, oy = 0.0f, oz = 0.0f;  ///< origin[kx], origin[ky], origin[kz]

  InlineWatertightRay() = default;
  explicit InlineWatertightRay(const Ray& ray) : wr(ray.direction) {
    const float* o = &ray.origin.x;
    ox = o[wr.kx];
    oy = o[wr.ky];
    oz = o[wr.kz];
  }
};

/// Same contract and results as intersect_watertight(ray, r.wr, tri, ...).
[[gnu::always_inline]] inline bool intersect_watertight_inline(const Ray& ray, const InlineWatertightRay& r,
                                                               const Triangle& tri, float tmin, float tmax, Hit& hit) {
  const WatertightRay& wr = r.wr;
  const float* p0 = &tri.v0.x;
  const float* p1 = &tri.v1.x;
  const float* p2 = &tri.v2.x;
  // Vertices relative to the origin, permuted: A[kx], A[ky], A[kz], ...
  const float Ax = p0[wr.kx] - r.ox, Ay = p0[wr.ky] - r.oy, Az = p0[wr.kz] - r.oz;
  const float Bx = p1[wr.kx] - r.ox, By = p1[wr.ky] - r.oy, Bz = p1[wr.kz] - r.oz;
  const float Cx = p2[wr.kx] - r.ox, Cy = p2[wr.ky] - r.oy, Cz = p2[wr.kz] - r.oz;
  const float ax = Ax - wr.sx * Az, ay = Ay - wr.sy * Az;
  const float bx = Bx - wr.sx * Bz, by = By - wr.sy * Bz;
  const float cx = Cx - wr.sx * Cz, cy = Cy - wr.sy * Cz;
  const float U = cx * by - cy * bx;
  const float V = ax * cy - ay * cx;
  const float W = bx * ay - by * ax;
  // Every special case of the out-of-line test goes back to it.
  if (U == 0.0f || V == 0.0f || W == 0.0f || !std::isfinite(U + V + W))
    return intersect_watertight(ray, wr, tri, tmin, tmax, hit);
  if ((U < 0.0f || V < 0.0f || W < 0.0f) && (U > 0.0f || V > 0.0f || W > 0.0f)) return false;
  const float det = U + V + W;
  if (det == 0.0f) return false;
  if (std::fabs(det) < kWatertightLowRange) return intersect_watertight(ray, wr, tri, tmin, tmax, hit);
  const float az = wr.sz * Az;
  const float bz = wr.sz * Bz;
  const float cz = wr.sz * Cz;
  const float T = U * az + V * bz + W * cz;
  if (!std::isfinite(T) || (std::fabs(T) < kWatertightLowRange && T != 0.0f))
    return intersect_watertight(ray, wr, tri, tmin, tmax, hit);
  return watertight_accept(V, W, det, T, tmin, tmax, hit);
}

/// Same contract and results as intersect_moller_trumbore (whose body it is,
/// core/geometry/triangle_inline.h).
using accelviz::intersect_moller_trumbore_inline;

/// The inline twin of triangle.cpp's test `Test`: same results (the BVH's leaves, brute force).
template <TriangleTest Test>
[[gnu::always_inline]] inline bool test_triangle(const Ray& ray, const InlineWatertightRay& wr, const Triangle& tri,
                                                 float tmin, float tmax, Hit& h) {
  if constexpr (Test == TriangleTest::watertight)
    return intersect_watertight_inline(ray, wr, tri, tmin, tmax, h);
  else
    return intersect_moller_trumbore_inline(ray, tri, tmin, tmax, h);
}

}  // namespace accelviz::bvh_detail
