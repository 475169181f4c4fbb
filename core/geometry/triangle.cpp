#include "core/geometry/triangle.h"

#include <cmath>

#include "core/geometry/triangle_inline.h"

namespace accelviz {

namespace {

// Steps 6 and 7 of the watertight test (inside test, distance) on sheared coordinates in double.
bool watertight_steps_in_double(double ax, double ay, double bx, double by, double cx, double cy, double az, double bz,
                                double cz, float tmin, float tmax, Hit& hit) {
  const double U = cx * by - cy * bx, V = ax * cy - ay * cx, W = bx * ay - by * ax;
  if ((U < 0.0 || V < 0.0 || W < 0.0) && (U > 0.0 || V > 0.0 || W > 0.0)) return false;
  const double det = U + V + W;
  if (det == 0.0 || !std::isfinite(det)) return false;
  const double T = U * az + V * bz + W * cz;
  const double t = T / det;
  if (!(t >= tmin && t <= tmax)) return false;
  hit.t = static_cast<float>(t);
  if (!(hit.t >= tmin && hit.t <= tmax)) hit.t = t < tmin ? tmin : tmax;  // keep the float t inside the interval
  hit.u = static_cast<float>(V / det);
  hit.v = static_cast<float>(W / det);
  return true;
}

// The whole watertight test in double precision, for triangles whose sheared float coordinates
// overflow (coordinates near 3e38). Shared vertices are still sheared by one and the same
// computation, so neighbouring triangles stay consistent with each other.
bool intersect_watertight_double(const Ray& ray, const WatertightRay& wr, const Triangle& tri, float tmin, float tmax,
                                 Hit& hit) {
  const glm::dvec3 o(ray.origin), d(ray.direction);
  const double sx = d[wr.kx] / d[wr.kz], sy = d[wr.ky] / d[wr.kz], sz = 1.0 / d[wr.kz];
  const glm::dvec3 A = glm::dvec3(tri.v0) - o, B = glm::dvec3(tri.v1) - o, C = glm::dvec3(tri.v2) - o;
  return watertight_steps_in_double(A[wr.kx] - sx * A[wr.kz], A[wr.ky] - sy * A[wr.kz], B[wr.kx] - sx * B[wr.kz],
                                    B[wr.ky] - sy * B[wr.kz], C[wr.kx] - sx * C[wr.kz], C[wr.ky] - sy * C[wr.kz],
                                    sz * A[wr.kz], sz * B[wr.kz], sz * C[wr.kz], tmin, tmax, hit);
}

// Steps 6 and 7 in double on the coordinates the float test sheared, for a candidate whose float
// figures leave float's range (edge functions or T under 1e-30, or beyond 3e38). The product of two
// floats is exact in double, so each edge function's sign is the exact one, which the float test
// also reads wherever it reads a sign (rounding keeps a sign or gives 0); two triangles that share
// an edge share its sheared vertices and read opposite signs. Redone from a fresh double shear
// (intersect_watertight_double), such an edge was decided on other coordinates than the
// neighbour's float test: a closed cube of half-size 1e-12, traced with unit directions through its
// shared vertices and edges, let 27 of 1,116 rays through.
bool watertight_sheared_double(float ax, float ay, float bx, float by, float cx, float cy, float az, float bz, float cz,
                               float tmin, float tmax, Hit& hit) {
  return watertight_steps_in_double(ax, ay, bx, by, cx, cy, az, bz, cz, tmin, tmax, hit);
}

bool finite6(float a, float b, float c, float d, float e, float f) {
  return std::isfinite(a) && std::isfinite(b) && std::isfinite(c) && std::isfinite(d) && std::isfinite(e) &&
         std::isfinite(f);
}

}  // namespace

bool intersect_watertight(const Ray& ray, const WatertightRay& wr, const Triangle& tri, float tmin, float tmax,
                          Hit& hit) {
  // 1. Vertices relative to the ray origin.
  const glm::vec3 A = tri.v0 - ray.origin;
  const glm::vec3 B = tri.v1 - ray.origin;
  const glm::vec3 C = tri.v2 - ray.origin;
  // 2. Shear and scale so the ray is the +z axis through the origin.
  const float ax = A[wr.kx] - wr.sx * A[wr.kz];
  const float ay = A[wr.ky] - wr.sy * A[wr.kz];
  const float bx = B[wr.kx] - wr.sx * B[wr.kz];
  const float by = B[wr.ky] - wr.sy * B[wr.kz];
  const float cx = C[wr.kx] - wr.sx * C[wr.kz];
  const float cy = C[wr.ky] - wr.sy * C[wr.kz];
  // 3. Scaled barycentrics (2D edge functions).
  float U = cx * by - cy * bx;
  float V = ax * cy - ay * cx;
  float W = bx * ay - by * ax;
  // The depths, scaled (step 7's); needed early by the double fallbacks.
  const float az = wr.sz * A[wr.kz];
  const float bz = wr.sz * B[wr.kz];
  const float cz = wr.sz * C[wr.kz];
  // 4. Overflow (huge coordinates): in double on the sheared coordinates where they are finite, else
  //    the whole test in double.
  if (!std::isfinite(U + V + W)) {
    if (finite6(ax, ay, bx, by, cx, cy) && std::isfinite(az) && std::isfinite(bz) && std::isfinite(cz))
      return watertight_sheared_double(ax, ay, bx, by, cx, cy, az, bz, cz, tmin, tmax, hit);
    return intersect_watertight_double(ray, wr, tri, tmin, tmax, hit);
  }
  // 5. An edge function of exactly zero is ambiguous in float: redo it in
  //    double from the same sheared float coordinates (the products are exact
  //    in double), as the paper prescribes.
  if (U == 0.0f || V == 0.0f || W == 0.0f) {
    const double Ud = static_cast<double>(cx) * by - static_cast<double>(cy) * bx;
    const double Vd = static_cast<double>(ax) * cy - static_cast<double>(ay) * cx;
    const double Wd = static_cast<double>(bx) * ay - static_cast<double>(by) * ax;
    U = static_cast<float>(Ud);
    V = static_cast<float>(Vd);
    W = static_cast<float>(Wd);
    // Below about 1e-22 the products underflow float altogether (1e-23 squared is under its smallest
    // denormal): every edge function read 0, "degenerate", and a scene of 1e-23 was missed by every ray.
    if ((U == 0.0f && Ud != 0.0) || (V == 0.0f && Vd != 0.0) || (W == 0.0f && Wd != 0.0))
      return watertight_sheared_double(ax, ay, bx, by, cx, cy, az, bz, cz, tmin, tmax, hit);
  }
  // 6. Inside test, both windings (no backface culling).
  if ((U < 0.0f || V < 0.0f || W < 0.0f) && (U > 0.0f || V > 0.0f || W > 0.0f)) return false;
  const float det = U + V + W;
  if (det == 0.0f) return false;  // degenerate, or ray in the triangle's plane
  // Edge functions are quadratic and T cubic in the coordinates: near the
  // bottom of the float range (tiny triangles, 1e-13 and below) they lose
  // their precision in denormals; redo such a candidate in double, on the same sheared coordinates.
  if (std::fabs(det) < kWatertightLowRange)
    return watertight_sheared_double(ax, ay, bx, by, cx, cy, az, bz, cz, tmin, tmax, hit);
  // 7. Scaled distance, compared against the scaled interval to avoid a division on misses.
  const float T = U * az + V * bz + W * cz;
  if (!std::isfinite(T) || (std::fabs(T) < kWatertightLowRange && T != 0.0f)) {
    if (std::isfinite(az) && std::isfinite(bz) && std::isfinite(cz))
      return watertight_sheared_double(ax, ay, bx, by, cx, cy, az, bz, cz, tmin, tmax, hit);
    return intersect_watertight_double(ray, wr, tri, tmin, tmax, hit);
  }
  return watertight_accept(V, W, det, T, tmin, tmax, hit);
}

bool intersect_moller_trumbore(const Ray& ray, const Triangle& tri, float tmin, float tmax, Hit& hit) {
  return intersect_moller_trumbore_inline(ray, tri, tmin, tmax, hit);
}

glm::vec3 triangle_normal(const Triangle& tri) {
  const glm::vec3 n = tri.cross_normal();
  const float len = glm::length(n);
  if (!(len > 0.0f) || !std::isfinite(len)) {
    // Very large or small coordinates can overflow/underflow the float cross
    // product; redo it in double before giving up.
    const glm::dvec3 a(tri.v0), b(tri.v1), c(tri.v2);
    const glm::dvec3 nd = glm::cross(b - a, c - a);
    const double l = glm::length(nd);
    if (!(l > 0.0) || !std::isfinite(l)) return glm::vec3(0.0f);
    return glm::vec3(nd / l);
  }
  return n / len;
}

}  // namespace accelviz
