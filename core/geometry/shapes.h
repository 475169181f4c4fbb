#pragma once
// Analytic primitives beside triangles: plane, sphere, finite capped cylinder.
// Each test accepts t in [tmin, tmax] and fills hit.t and hit.ng (unit, pointing
// out of the solid / along the plane normal); prim is left to the caller.
#include <glm/glm.hpp>

#include "core/geometry/hit.h"
#include "core/geometry/triangle.h"

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
/// towards (flip it by the ray direction first). `scale`: the magnitude of
/// the coordinates `p` was computed from (the hit triangle's largest |vertex
/// coordinate|; the ray's origin's and the point's): below 1, the
/// near-origin threshold (1/32) and offset (1/65536), Wachter & Binder's for
/// coordinates of about 1, shrink with it, so a scene of 1e-5 is offset as one
/// of 1 is (their absolute 1/65536 put its shadow rays' origins beyond the
/// scene, and none was traced). At 1 and above: their published offsets.
glm::vec3 offset_ray_origin(const glm::vec3& p, const glm::vec3& n, float scale = 1.0f);

/// The largest |coordinate| of the triangle's vertices: offset_ray_origin's
/// `scale` for a point computed from them.
float coordinate_scale(const Triangle& t);

}  // namespace accelviz
