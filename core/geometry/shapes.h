#pragma once
// Analytic primitives beside triangles: plane, sphere, finite capped cylinder.
// Each test accepts t in [tmin, tmax] and fills hit.t and hit.ng (unit, pointing
// out of the solid / along the plane normal); prim is left to the caller.
#include "core/geometry/hit.h"

#include <glm/glm.hpp>

namespace accelviz {

struct Plane {
  glm::vec3 point{0.0f};
  glm::vec3 normal{0.0f, 1.0f, 0.0f};  ///< need not be unit length
};

struct Sphere {
  glm::vec3 center{0.0f};
  float radius = 1.0f;
};

/// A finite cylinder with flat caps: axis from `base` along unit `axis` for
/// `height`, radius `radius`. Any centre and orientation.
struct Cylinder {
  glm::vec3 base{0.0f};
  glm::vec3 axis{0.0f, 1.0f, 0.0f};
  float radius = 1.0f;
  float height = 1.0f;
};

bool intersect_plane(const Ray& ray, const Plane& plane, float tmin, float tmax, Hit& hit);
/// Robust quadratic: solved relative to the closest point of the ray to the
/// centre, which keeps precision for spheres far from the ray origin.
bool intersect_sphere(const Ray& ray, const Sphere& sphere, float tmin, float tmax, Hit& hit);
bool intersect_cylinder(const Ray& ray, const Cylinder& cyl, float tmin, float tmax, Hit& hit);

/// Offsets a point on a surface along the geometric normal so that a
/// secondary ray starting there does not re-hit the same surface.
/// Scale-aware (Wachter & Binder, "A Fast and Robust Method for Avoiding
/// Self-Intersection", Ray Tracing Gems 2019): near the origin a tiny absolute
/// offset, elsewhere a fixed number of float ULPs of each coordinate, so it
/// works at 1e-3 and at 1e7 alike. `n` must point to the side the ray leaves
/// towards (flip it by the ray direction first).
glm::vec3 offset_ray_origin(const glm::vec3& p, const glm::vec3& n);

}  // namespace accelviz
