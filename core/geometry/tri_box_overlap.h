#pragma once
// Exact triangle / axis-aligned box overlap, and the bounds of a triangle
// clipped to a box. The spatial structures (grid, octree, voxels) decide
// which cells reference a triangle with the first; the K-D tree's "perfect
// splits" (Havran 2000; Wald & Havran 2006) use the second.
#include "core/geometry/triangle.h"
#include "core/math/aabb.h"

#include <cmath>

namespace accelviz {

/// True when the triangle and the closed box share at least one point.
///
/// Separating-axis test of Akenine-Möller ("Fast 3D Triangle-Box Overlap
/// Testing", JGT 2001): the box normals, the triangle normal and the nine
/// cross products of box axes with triangle edges. Two deliberate changes:
///  - every axis projects all three vertices (the paper projects two per
///    edge axis and one for the plane test because the others coincide in
///    exact arithmetic). Any axis whatsoever is a valid separating-axis
///    candidate, so a degenerate or needle triangle whose computed normal is
///    rounding noise, or zero, can never be separated by a wrong axis: zero
///    axes separate nothing and the test falls back to the box axes and the
///    edge axes, which is the full test for a segment or a point.
///  - the arithmetic is in double, and an axis only separates when the gap
///    exceeds a bound on the rounding error (about 1e-12 relative). So the
///    answer errs, if ever, towards "overlap", and touching (a shared vertex,
///    edge or face) counts as overlap.
/// Non-finite vertices never overlap anything; an empty box overlaps nothing.
bool triangle_box_overlap(const Triangle& tri, const Aabb& box);

/// Bounds of the part of the triangle inside the closed box (Sutherland-
/// Hodgman clipping against the six planes, in double), rounded outward to
/// float and clamped to both the box and the triangle's own bounds. Returns
/// Aabb::empty() when the clipped polygon is empty. A triangle already inside
/// the box returns its own bounds unchanged, and coordinates on a clipping
/// plane are set to the plane value exactly, so planar triangles stay planar.
Aabb clipped_triangle_bounds(const Triangle& tri, const Aabb& box);

/// The box grown by `pad` on every side (pad >= 0).
inline Aabb padded_box(const Aabb& b, float pad) { return {b.lo - glm::vec3(pad), b.hi + glm::vec3(pad)}; }

/// True when all nine coordinates are finite.
inline bool is_finite_triangle(const Triangle& t) {
  const auto ok = [](const glm::vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
  };
  return ok(t.v0) && ok(t.v1) && ok(t.v2);
}

}  // namespace accelviz
