#include "core/geometry/shapes.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

namespace accelviz {

bool intersect_plane(const Ray& ray, const Plane& plane, float tmin, float tmax, Hit& hit) {
  const float denom = glm::dot(plane.normal, ray.direction);
  if (denom == 0.0f) return false;  // parallel (including lying in the plane)
  const float t = glm::dot(plane.normal, plane.point - ray.origin) / denom;
  if (!(t >= tmin && t <= tmax)) return false;
  hit.t = t;
  hit.u = hit.v = 0.0f;
  hit.ng = glm::normalize(plane.normal);
  return true;
}

bool intersect_sphere(const Ray& ray, const Sphere& s, float tmin, float tmax, Hit& hit) {
  // Work in double: the sphere test is not on a hot path and this removes
  // the catastrophic cancellation of b^2 - 4ac for distant spheres.
  const glm::dvec3 o(ray.origin), d(ray.direction), c(s.center);
  const double r = s.radius;
  const double dd = glm::dot(d, d);
  if (!(dd > 0.0)) return false;
  const glm::dvec3 oc = o - c;
  const double b = glm::dot(oc, d);
  // Closest approach point: f = oc - (b/dd) d; disc = r^2 - |f|^2 (Hearn & Baker / pbrt-v4).
  const glm::dvec3 f = oc - (b / dd) * d;
  const double disc = r * r - glm::dot(f, f);
  if (disc < 0.0) return false;
  const double sq = std::sqrt(disc * dd);
  const double q = (b > 0.0) ? -(b + sq) : -(b - sq);
  double t0 = q / dd;
  double t1 = (q != 0.0) ? (glm::dot(oc, oc) - r * r) / q : t0;
  if (t0 > t1) std::swap(t0, t1);
  double t = t0;
  if (t < tmin || t > tmax) {
    t = t1;
    if (t < tmin || t > tmax) return false;
  }
  hit.t = static_cast<float>(t);
  hit.u = hit.v = 0.0f;
  hit.ng = glm::vec3(glm::normalize(o + t * d - c));
  return true;
}

bool intersect_cylinder(const Ray& ray, const Cylinder& cyl, float tmin, float tmax, Hit& hit) {
  // Express the ray in the cylinder's frame: axial coordinate along `axis`,
  // radial part perpendicular to it. Double precision for the same reason as the sphere.
  const glm::dvec3 axis = glm::normalize(glm::dvec3(cyl.axis));
  const glm::dvec3 o = glm::dvec3(ray.origin) - glm::dvec3(cyl.base);
  const glm::dvec3 d(ray.direction);
  const double oa = glm::dot(o, axis), da = glm::dot(d, axis);
  const glm::dvec3 orad = o - oa * axis, drad = d - da * axis;
  const double r = cyl.radius, h = cyl.height;

  double best = kInfinity;
  glm::dvec3 best_n(0.0);
  auto consider = [&](double t, const glm::dvec3& n) {
    if (t >= tmin && t <= tmax && t < best) {
      best = t;
      best_n = n;
    }
  };
  // Lateral surface: |orad + t drad|^2 = r^2, with 0 <= axial <= h.
  const double a = glm::dot(drad, drad);
  if (a > 0.0) {
    const double b = glm::dot(orad, drad);
    const glm::dvec3 f = orad - (b / a) * drad;
    const double disc = r * r - glm::dot(f, f);
    if (disc >= 0.0) {
      const double sq = std::sqrt(disc * a);
      const double q = (b > 0.0) ? -(b + sq) : -(b - sq);
      const double roots[2] = {q / a, (q != 0.0) ? (glm::dot(orad, orad) - r * r) / q : q / a};
      for (double t : roots) {
        const double axial = oa + t * da;
        if (axial >= 0.0 && axial <= h) consider(t, glm::normalize(orad + t * drad));
      }
    }
  }
  // Caps: planes axial = 0 (normal -axis) and axial = h (normal +axis).
  if (da != 0.0) {
    for (int cap = 0; cap < 2; ++cap) {
      const double t = ((cap ? h : 0.0) - oa) / da;
      const glm::dvec3 pr = orad + t * drad;
      if (glm::dot(pr, pr) <= r * r) consider(t, cap ? axis : -axis);
    }
  }
  if (best == kInfinity) return false;
  hit.t = static_cast<float>(best);
  hit.u = hit.v = 0.0f;
  hit.ng = glm::vec3(best_n);
  return true;
}

glm::vec3 offset_ray_origin(const glm::vec3& p, const glm::vec3& n, float scale) {
  // Constants from Wachter & Binder 2019: below |1/32| move by a small
  // absolute amount, otherwise move each coordinate by 256·|n_i| ULPs; for
  // coordinates of magnitude `scale` < 1 both absolute figures shrink with it.
  const float s = scale > 0.0f && scale < 1.0f ? scale : 1.0f;  // NaN: 1
  const float kOrigin = s / 32.0f;
  const float kFloatScale = s / 65536.0f;
  constexpr float kIntScale = 256.0f;
  glm::vec3 out;
  for (int i = 0; i < 3; ++i) {
    const int of_i = static_cast<int>(kIntScale * n[i]);
    const std::int32_t bits = std::bit_cast<std::int32_t>(p[i]);
    // Moving away from zero adds ULPs to the magnitude; towards zero subtracts.
    const float p_i = std::bit_cast<float>(bits + ((p[i] < 0.0f) ? -of_i : of_i));
    out[i] = std::fabs(p[i]) < kOrigin ? p[i] + kFloatScale * n[i] : p_i;
  }
  return out;
}

float coordinate_scale(const Triangle& t) {
  float m = 0.0f;
  for (const glm::vec3* v : {&t.v0, &t.v1, &t.v2}) m = std::max({m, std::fabs(v->x), std::fabs(v->y), std::fabs(v->z)});
  return m;
}

}  // namespace accelviz
