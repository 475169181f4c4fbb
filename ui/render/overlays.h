#pragma once
// What the overlay passes draw, as plain data built from core results:
// translucent quads (K-D split planes, grid slices) and the path of one ray
// through a structure (for the ray inspector).
#include "core/accel/accel.h"
#include "core/accel/bvh/bvh.h"
#include "core/geometry/hit.h"
#include "core/math/aabb.h"
#include "core/math/ray.h"

#include <glm/glm.hpp>

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace accelviz {

/// A world-space vertex with a colour: the layout of shaders/colored.vert.
struct ColoredVertex {
  glm::vec3 position{0.0f};
  glm::vec4 color{1.0f};
};
static_assert(sizeof(ColoredVertex) == 28, "ColoredVertex is uploaded as is: xyz(12) rgba(16)");

/// A planar quad drawn translucent (no depth writes, so what lies behind
/// stays visible), with an optional opaque-ish outline.
struct TranslucentQuad {
  std::array<glm::vec3, 4> corners{};  ///< in order around the quad
  glm::vec4 fill{0.3f, 0.6f, 1.0f, 0.25f};
  glm::vec4 outline{0.3f, 0.6f, 1.0f, 0.0f};  ///< alpha 0: no outline
};

/// The plane `axis` = `position` clipped to `box` (a K-D tree split), as a quad.
TranslucentQuad split_plane_quad(const Aabb& box, int axis, float position, const glm::vec4& fill,
                                 const glm::vec4& outline);

struct RayPathStyle {
  glm::vec4 path{1.0f, 0.85f, 0.1f, 1.0f};         ///< the polyline
  glm::vec4 hit_marker{1.0f, 0.15f, 0.15f, 1.0f};  ///< the point at the hit
  glm::vec4 normal{0.3f, 0.7f, 1.0f, 1.0f};        ///< the normal line at the hit
  glm::vec4 highlight{1.0f, 0.45f, 0.1f, 1.0f};    ///< highlighted primitives
  // Saturated and dark enough to read on the white mesh and the dark background alike.
  glm::vec4 first_visit{0.1f, 0.4f, 1.0f, 1.0f};   ///< first visited box (blue)...
  glm::vec4 last_visit{0.9f, 0.1f, 0.8f, 1.0f};    ///< ...fading to the last (magenta: the current step's)
  float marker_px = 7.0f;                          ///< hit marker size in pixels
};

/// The path of one ray, in world space.
struct RayPath {
  std::vector<glm::vec3> polyline;  ///< origin, ..., end (hit point, or where the ray leaves the scene)
  bool hit = false;
  glm::vec3 hit_point{0.0f};
  glm::vec3 hit_normal{0.0f};              ///< unit, facing back along the ray
  float normal_length = 1.0f;              ///< world units
  std::vector<Aabb> visited;               ///< boxes in visiting order (drawn fading from first to last)
  std::vector<std::uint32_t> highlighted;  ///< primitive ids (indices into the scene's triangles)
  RayPathStyle style;
};

/// The path of `ray` up to `hit`; on a miss, up to where it leaves
/// `scene_bounds` (or a scene diagonal past the box's centre when it misses
/// the box too). The normal line is a tenth of the scene diagonal long.
/// `visited` and `highlighted` are left for the caller (see below).
RayPath make_ray_path(const Ray& ray, const Hit& hit, const Aabb& scene_bounds);

/// Boxes of the BVH nodes a traced ray entered, in visiting order.
std::vector<Aabb> entered_boxes(const VisitTrace& trace, std::span<const BvhNode> nodes);

/// Primitives a traced ray tested, each once, in first-test order.
std::vector<std::uint32_t> tested_primitives(const VisitTrace& trace);

}  // namespace accelviz
