#pragma once
// Triangulating one planar polygon (an OBJ face of four or more vertices).
#include <array>
#include <cstdint>
#include <glm/vec3.hpp>
#include <span>
#include <vector>

namespace accelviz {

/// n − 2 triangles over the polygon's corners (indices into `corners`, in the
/// polygon's winding). A convex quad (or a polygon with no usable plane) is
/// fan-triangulated from its first corner: (0, k, k+1) (flat corners, on the straight line
/// between their neighbours, are fanned in from the triangles of the other corners' cut, so no
/// triangle has zero area, up to 8 per triangle: polygon.cpp fan_sides); a convex polygon of
/// five or more corners is cut by (0, t, 2t), t = (n+1)/3, and each arc left
/// by (first, middle, last) and its halves the same way, so that a
/// many-cornered face is not n − 2 slivers from one corner (fatter
/// triangles, fewer overlapping boxes). A concave one is
/// ear-clipped in the plane of its Newell normal, so no triangle covers area
/// outside the polygon (a fan of a U shape covered its notch), round by round
/// around the outline, passing over corners found to be no ear until a
/// neighbour is cut and checking only the reflex corners each ear's triangle
/// spans (100,000-corner combs, zig-zags and spirals take well under a
/// second); where no ear is found (a self-intersecting outline) the rest is
/// fanned.
std::vector<std::array<std::uint32_t, 3>> triangulate_polygon(std::span<const glm::vec3> corners);

}  // namespace accelviz
