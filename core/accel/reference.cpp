#include "core/accel/reference.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace accelviz {

namespace {

// What the watertight test derives from the ray alone, computed once per ray
// (the brute force over every triangle repeated it per triangle).
struct ReferenceRay {
  glm::dvec3 o;
  int kx = 0, ky = 1, kz = 2;
  double sx = 0.0, sy = 0.0, sz = 0.0;
  double o_mx = 0.0, o_my = 0.0;  ///< the translation's rounding magnitudes (step 2)
  bool zero = false;              ///< zero dominant direction component: nothing is hit
};

ReferenceRay prepare_reference_ray(const Ray& ray) {
  ReferenceRay r;
  r.o = glm::dvec3(ray.origin);
  const glm::dvec3 d(ray.direction);
  // 1. Permute so the dominant direction axis is z (swap x/y to keep the
  //    winding when it is negative), exactly as the float test does.
  const glm::dvec3 a = glm::abs(d);
  r.kz = (a.x > a.y) ? (a.x > a.z ? 0 : 2) : (a.y > a.z ? 1 : 2);
  r.kx = (r.kz + 1) % 3;
  r.ky = (r.kx + 1) % 3;
  if (d[r.kz] == 0.0) {
    r.zero = true;
    return r;
  }
  if (d[r.kz] < 0.0) std::swap(r.kx, r.ky);
  r.sx = d[r.kx] / d[r.kz];
  r.sy = d[r.ky] / d[r.kz];
  r.sz = 1.0 / d[r.kz];
  // Float rounding of the translation itself is relative to the coordinates'
  // absolute size (a scene far from the origin loses bits there).
  r.o_mx = std::abs(r.o[r.kx]) + std::abs(r.sx * r.o[r.kz]);
  r.o_my = std::abs(r.o[r.ky]) + std::abs(r.sy * r.o[r.kz]);
  return r;
}

ReferenceTriangleHit intersect_prepared(const ReferenceRay& rr, const Triangle& tri, double tmin, double tmax) {
  ReferenceTriangleHit r;
  if (rr.zero) return r;
  const glm::dvec3& o = rr.o;
  const int kx = rr.kx, ky = rr.ky, kz = rr.kz;
  const double sx = rr.sx, sy = rr.sy, sz = rr.sz;

  // 2. Translate to the origin and shear so the ray runs along +z.
  const glm::dvec3 p[3] = {glm::dvec3(tri.v0) - o, glm::dvec3(tri.v1) - o, glm::dvec3(tri.v2) - o};
  double x[3], y[3], z[3], mx[3], my[3], mz[3];
  for (int i = 0; i < 3; ++i) {
    x[i] = p[i][kx] - sx * p[i][kz];
    y[i] = p[i][ky] - sy * p[i][kz];
    z[i] = sz * p[i][kz];
    // Magnitudes the float test rounds: the shear's terms, not their difference,
    // plus the translation's (rr.o_mx, rr.o_my).
    mx[i] = std::abs(p[i][kx]) + std::abs(sx * p[i][kz]);
    my[i] = std::abs(p[i][ky]) + std::abs(sy * p[i][kz]);
    mz[i] = std::abs(z[i]);
    mx[i] += rr.o_mx;
    my[i] += rr.o_my;
  }

  // 3. Edge functions (signed areas), exact enough in double, with the size
  //    of the rounding a float evaluation could put on each.
  const double e[3] = {x[2] * y[1] - y[2] * x[1], x[0] * y[2] - y[0] * x[2], x[1] * y[0] - y[1] * x[0]};
  // The float test's shear constants sx, sy underflow (a denormal direction component beside a
  // large one): an absolute rounding of up to float's smallest step, times |p_z|, on each sheared
  // coordinate, which the relative term above does not cover (every float structure was condemned
  // on such rays). u[i] bounds it; in e = x_a y_b - y_a x_b it adds u_a my_b + mx_a u_b + ...
  double u[3];
  for (int i = 0; i < 3; ++i) u[i] = static_cast<double>(std::numeric_limits<float>::denorm_min()) * std::abs(p[i][kz]);
  const auto under = [&](int a, int b) { return u[a] * (my[b] + mx[b]) + u[b] * (mx[a] + my[a]) + 2.0 * u[a] * u[b]; };
  const double tol[3] = {kEdgeRoundingScale * (mx[2] * my[1] + my[2] * mx[1]) + under(2, 1),
                         kEdgeRoundingScale * (mx[0] * my[2] + my[0] * mx[2]) + under(0, 2),
                         kEdgeRoundingScale * (mx[1] * my[0] + my[1] * mx[0]) + under(1, 0)};
  const bool neg = e[0] < 0.0 || e[1] < 0.0 || e[2] < 0.0;
  const bool pos = e[0] > 0.0 || e[1] > 0.0 || e[2] > 0.0;
  const double det = e[0] + e[1] + e[2];
  bool near_edge = false;
  bool widened_inside_pos = true, widened_inside_neg = true;
  for (int i = 0; i < 3; ++i) {
    near_edge = near_edge || std::abs(e[i]) <= tol[i];
    widened_inside_pos = widened_inside_pos && e[i] >= -tol[i];
    widened_inside_neg = widened_inside_neg && e[i] <= tol[i];
  }
  // Outside by more than rounding on both windings: neither a hit nor a near
  // miss, whatever t is (the usual answer of a brute force, so skip the rest).
  if (!widened_inside_pos && !widened_inside_neg) return r;
  const double det_tol = tol[0] + tol[1] + tol[2];
  const bool inside = !(neg && pos) && det != 0.0;

  // 4. Distance, and the rounding a float evaluation could put on it:
  //    t = (sum e_i z_i) / det, each factor carrying its tolerance.
  const double tsum = e[0] * z[0] + e[1] * z[1] + e[2] * z[2];
  const double t = det != 0.0 ? tsum / det : std::numeric_limits<double>::infinity();
  double t_err = std::numeric_limits<double>::infinity();
  if (std::abs(det) > det_tol) {
    double tsum_err = 0.0;
    for (int i = 0; i < 3; ++i) tsum_err += tol[i] * mz[i] + std::abs(e[i]) * mz[i] * kEdgeRoundingScale;
    t_err = (tsum_err + std::abs(t) * det_tol) / (std::abs(det) - det_tol);
  }
  r.t = t;
  r.t_tolerance = std::max(kTTolerance * std::max(1.0, std::abs(t)), t_err);
  r.near_edge = near_edge;
  const bool t_in = t >= tmin && t <= tmax;
  const bool t_near = std::isfinite(t) ? (t >= tmin - r.t_tolerance && t <= tmax + r.t_tolerance) : false;
  if (inside && t_in) {
    r.hit = true;
    return r;
  }
  // A miss decided by rounding: inside once each edge is widened by its
  // tolerance (this includes rays in the triangle's plane, det ~ 0), or a hit
  // just outside [tmin, tmax].
  if ((widened_inside_pos || widened_inside_neg) && (near_edge || std::abs(det) <= det_tol)) {
    r.near_miss = !std::isfinite(t) || std::abs(det) <= det_tol || t_near;
    if (std::abs(det) <= det_tol) r.t_tolerance = std::numeric_limits<double>::infinity();
  } else if (inside && t_near) {
    r.near_miss = true;
  }
  return r;
}

}  // namespace

ReferenceTriangleHit intersect_reference(const Ray& ray, const Triangle& tri, double tmin, double tmax) {
  return intersect_prepared(prepare_reference_ray(ray), tri, tmin, tmax);
}

void fold_reference_hit(ReferenceHit& best, const ReferenceTriangleHit& h, std::uint32_t id, const Ray& ray) {
  if (h.hit) {
    best.near_hit = true;
    // A hit at t within rounding of tmin or tmax (origin on the surface,
    // a shadow ray ending on it) is a rounding decision too.
    const bool t_inside = h.t - h.t_tolerance > ray.tmin && h.t + h.t_tolerance < ray.tmax;
    best.robust_hit = best.robust_hit || (!h.near_edge && t_inside);
    if (h.t < best.t || (h.t == best.t && id < best.prim)) {
      best.prim = id;
      best.t = h.t;
      best.t_tolerance = h.t_tolerance;
      best.closest_near_edge = h.near_edge;
    }
  } else if (h.near_miss) {
    best.near_hit = true;
  }
}

ReferenceHit ReferenceTracer::closest_hit(const Ray& ray) const {
  ReferenceHit best;
  const ReferenceRay rr = prepare_reference_ray(ray);
  for (std::size_t i = 0; i < tris_.size(); ++i)
    fold_reference_hit(best, intersect_prepared(rr, tris_[i], ray.tmin, ray.tmax), static_cast<std::uint32_t>(i), ray);
  return best;
}

bool ReferenceTracer::any_hit(const Ray& ray) const {
  const ReferenceRay rr = prepare_reference_ray(ray);
  for (const Triangle& tri : tris_)
    if (intersect_prepared(rr, tri, ray.tmin, ray.tmax).hit) return true;
  return false;
}

const char* to_string(Verdict v) {
  switch (v) {
    case Verdict::match:
      return "match";
    case Verdict::near_tie:
      return "near_tie";
    case Verdict::mismatched_prim:
      return "mismatched_prim";
    case Verdict::t_beyond_tolerance:
      return "t_beyond_tolerance";
  }
  return "?";
}

bool same_t(double a, double b, double tolerance) {
  if (a == b) return true;
  const double scale = std::max({1.0, std::abs(a), std::abs(b)});
  return std::abs(a - b) <= std::max(tolerance, kTTolerance * scale);
}

Verdict classify_closest(std::span<const Triangle> triangles, const Ray& ray, const ReferenceHit& ref, const Hit& got) {
  if (!got.valid() && !ref.valid()) return Verdict::match;
  if (!got.valid())  // a miss is excusable only when every hit was an edge decision
    return ref.robust_hit ? Verdict::mismatched_prim : Verdict::near_tie;
  if (got.prim >= triangles.size()) return Verdict::mismatched_prim;
  if (ref.valid() && got.prim == ref.prim)
    return same_t(got.t, ref.t, ref.t_tolerance) ? Verdict::match : Verdict::t_beyond_tolerance;
  // Different primitive (or a hit where the reference misses). Equal t is a
  // tie between neighbours (shared edge or vertex, duplicates).
  if (ref.valid() && same_t(got.t, ref.t, ref.t_tolerance)) return Verdict::near_tie;
  // Otherwise recompute the structure's primitive in double: it must be a
  // hit or a rounding-close miss at the t the structure reported, and the
  // reference's own closer hit (if the structure went past it) must have been
  // an edge decision.
  const ReferenceTriangleHit mine = intersect_reference(ray, triangles[got.prim], ray.tmin, ray.tmax);
  if (!(mine.hit || mine.near_miss) || !same_t(got.t, mine.t, mine.t_tolerance)) return Verdict::mismatched_prim;
  // The near tie of the rule: the structure's primitive lies at the
  // reference's t in double.
  if (ref.valid() && same_t(mine.t, ref.t, std::max(ref.t_tolerance, mine.t_tolerance))) return Verdict::near_tie;
  if (!ref.valid()) return mine.near_miss ? Verdict::near_tie : Verdict::mismatched_prim;
  if (got.t < ref.t) return mine.near_miss ? Verdict::near_tie : Verdict::mismatched_prim;
  // Skipping the reference's closer hit is a rounding decision when that hit
  // was on an edge, or at tmin (the origin lies on that surface).
  const bool closest_at_tmin = ref.t - ref.t_tolerance <= ray.tmin;
  return ref.closest_near_edge || closest_at_tmin ? Verdict::near_tie : Verdict::mismatched_prim;
}

Verdict classify_any(const ReferenceHit& ref, bool got) {
  if (got == ref.valid()) return Verdict::match;
  if (got) return ref.near_hit ? Verdict::near_tie : Verdict::mismatched_prim;
  return ref.robust_hit ? Verdict::mismatched_prim : Verdict::near_tie;
}

}  // namespace accelviz
