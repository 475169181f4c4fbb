#include "core/geometry/tri_box_overlap.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace accelviz {

namespace {

// Relative size of the rounding-error allowance on a projection. The double
// products carry errors around 1e-16 of |axis|·|v|; 1e-12 leaves a wide
// margin and is still far below anything geometry can resolve in float.
constexpr double kSatTolerance = 1e-12;

}  // namespace

bool triangle_box_overlap(const Triangle& tri, const Aabb& box) {
  if (box.is_empty() || !is_finite_triangle(tri)) return false;

  // Work relative to the box centre, so the box is [-h, h].
  const glm::dvec3 c = (glm::dvec3(box.lo) + glm::dvec3(box.hi)) * 0.5;
  const glm::dvec3 h = (glm::dvec3(box.hi) - glm::dvec3(box.lo)) * 0.5;
  const std::array<glm::dvec3, 3> v = {glm::dvec3(tri.v0) - c, glm::dvec3(tri.v1) - c, glm::dvec3(tri.v2) - c};

  // Magnitude scale for the error allowance.
  double scale = std::max({h.x, h.y, h.z});
  for (const glm::dvec3& p : v) scale = std::max({scale, std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)});

  // An axis separates when the projected triangle interval lies entirely
  // beyond the projected box radius, by more than the error allowance.
  const auto separated = [&](const glm::dvec3& axis) {
    const double p0 = glm::dot(axis, v[0]);
    const double p1 = glm::dot(axis, v[1]);
    const double p2 = glm::dot(axis, v[2]);
    const double r = h.x * std::fabs(axis.x) + h.y * std::fabs(axis.y) + h.z * std::fabs(axis.z);
    const double tol = kSatTolerance * scale * (std::fabs(axis.x) + std::fabs(axis.y) + std::fabs(axis.z));
    return std::min({p0, p1, p2}) > r + tol || std::max({p0, p1, p2}) < -r - tol;
  };

  // 1. The three box normals: the triangle's bounds against the box.
  for (int a = 0; a < 3; ++a) {
    const double lo = std::min({v[0][a], v[1][a], v[2][a]});
    const double hi = std::max({v[0][a], v[1][a], v[2][a]});
    const double tol = kSatTolerance * scale;
    if (lo > h[a] + tol || hi < -h[a] - tol) return false;
  }

  // 2. The nine cross products e_a × edge (a zero edge gives a zero axis,
  //    which separates nothing).
  const std::array<glm::dvec3, 3> edges = {v[1] - v[0], v[2] - v[1], v[0] - v[2]};
  for (const glm::dvec3& e : edges) {
    if (separated({0.0, -e.z, e.y})) return false;  // x × e
    if (separated({e.z, 0.0, -e.x})) return false;  // y × e
    if (separated({-e.y, e.x, 0.0})) return false;  // z × e
  }

  // 3. The triangle's normal (zero for a degenerate triangle).
  if (separated(glm::cross(edges[0], edges[1]))) return false;
  return true;
}

Aabb clipped_triangle_bounds(const Triangle& tri, const Aabb& box) {
  if (box.is_empty() || !is_finite_triangle(tri)) return Aabb::empty();
  const Aabb tb = tri.bounds();
  if (box.contains(tb)) return tb;
  const Aabb limit = Aabb::intersection(tb, box);
  if (limit.is_empty()) return Aabb::empty();

  // Sutherland-Hodgman against each plane the triangle crosses. A triangle
  // clipped by six planes has at most 3 + 6 = 9 vertices.
  constexpr int kMaxVerts = 9;
  std::array<glm::dvec3, kMaxVerts + 1> poly{glm::dvec3(tri.v0), glm::dvec3(tri.v1), glm::dvec3(tri.v2)};
  std::array<glm::dvec3, kMaxVerts + 1> next{};
  int n = 3;
  for (int a = 0; a < 3 && n > 0; ++a) {
    for (int side = 0; side < 2 && n > 0; ++side) {
      const bool lower = side == 0;
      const double plane = lower ? box.lo[a] : box.hi[a];
      if (lower ? tb.lo[a] >= box.lo[a] : tb.hi[a] <= box.hi[a]) continue;  // nothing beyond this plane
      const auto inside = [&](const glm::dvec3& p) { return lower ? p[a] >= plane : p[a] <= plane; };
      int m = 0;
      for (int i = 0; i < n; ++i) {
        const glm::dvec3& p = poly[i];
        const glm::dvec3& q = poly[(i + 1) % n];
        const bool in_p = inside(p), in_q = inside(q);
        if (in_p) next[m++] = p;
        if (in_p != in_q) {
          const double t = (plane - p[a]) / (q[a] - p[a]);
          glm::dvec3 r = p + t * (q - p);
          r[a] = plane;  // exactly on the plane, so clipped coordinates stay planar
          next[m++] = r;
        }
      }
      poly = next;
      n = std::min(m, kMaxVerts);
    }
  }
  if (n == 0) return Aabb::empty();

  glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
  for (int i = 0; i < n; ++i) {
    lo = glm::min(lo, poly[i]);
    hi = glm::max(hi, poly[i]);
  }
  // Round outward to float, with a hair of slack for the interpolation's own
  // rounding, then clamp: the result never leaves box ∩ triangle bounds.
  Aabb out;
  for (int a = 0; a < 3; ++a) {
    const double slack = 1e-15 * std::max({std::fabs(lo[a]), std::fabs(hi[a]), 1e-30});
    const double dlo = lo[a] == limit.lo[a] ? lo[a] : lo[a] - slack;
    const double dhi = hi[a] == limit.hi[a] ? hi[a] : hi[a] + slack;
    float flo = static_cast<float>(dlo), fhi = static_cast<float>(dhi);
    if (static_cast<double>(flo) > dlo) flo = std::nextafter(flo, -kInfinity);
    if (static_cast<double>(fhi) < dhi) fhi = std::nextafter(fhi, kInfinity);
    out.lo[a] = std::clamp(flo, limit.lo[a], limit.hi[a]);
    out.hi[a] = std::clamp(fhi, limit.lo[a], limit.hi[a]);
  }
  return out;
}

}  // namespace accelviz
