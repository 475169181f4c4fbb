#pragma once
// The float steps of the ray/triangle tests as inline functions, shared by
// core/geometry/triangle.cpp (the out-of-line tests) and the BVH's inlined
// traversal tests (core/accel/bvh/bvh_triangle.h), so both compute the same
// operations in the same order and give bit-identical results.
#include <cmath>

#include "core/geometry/triangle.h"

namespace accelviz {

/// Below this magnitude the watertight test's float det and T lose their
/// precision in denormals; such candidates are redone in double.
inline constexpr float kWatertightLowRange = 1e-30f;

/// The watertight test's last step, once det (= U + V + W, nonzero) and the
/// scaled distance T are known and usable: T against the scaled interval
/// (no division on misses), then t, u, v.
[[gnu::always_inline]] inline bool watertight_accept(float V, float W, float det, float T, float tmin, float tmax,
                                                     Hit& hit) {
  if (det > 0.0f) {
    if (T < tmin * det || T > tmax * det) return false;
  } else {
    if (T > tmin * det || T < tmax * det) return false;
  }
  const float rcp = 1.0f / det;
  const float t = T * rcp;
  if (!(t >= tmin && t <= tmax)) return false;  // guards rounding of the scaled compare and inf/NaN
  hit.t = t;
  hit.u = V * rcp;
  hit.v = W * rcp;
  return true;
}

/// Moller-Trumbore, no epsilon beyond det == 0: the body of
/// intersect_moller_trumbore, visible to the inliner.
[[gnu::always_inline]] inline bool intersect_moller_trumbore_inline(const Ray& ray, const Triangle& tri, float tmin,
                                                                    float tmax, Hit& hit) {
  const glm::vec3 e1 = tri.v1 - tri.v0;
  const glm::vec3 e2 = tri.v2 - tri.v0;
  const glm::vec3 p = glm::cross(ray.direction, e2);
  const float det = glm::dot(e1, p);
  if (det == 0.0f) return false;
  const float inv = 1.0f / det;
  const glm::vec3 s = ray.origin - tri.v0;
  const float u = glm::dot(s, p) * inv;
  if (u < 0.0f || u > 1.0f) return false;
  const glm::vec3 q = glm::cross(s, e1);
  const float v = glm::dot(ray.direction, q) * inv;
  if (v < 0.0f || u + v > 1.0f) return false;
  const float t = glm::dot(e2, q) * inv;
  if (!(t >= tmin && t <= tmax)) return false;
  hit.t = t;
  hit.u = u;
  hit.v = v;
  return true;
}

}  // namespace accelviz
