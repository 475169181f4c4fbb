#pragma once
// Small helpers that every procedural generator uses to assemble a Scene:
// meshes placed by root nodes (one instance per node, in node order),
// cameras that frame a box, lights, and the final flatten.
#include "core/scene/procedural/spec.h"
#include "core/scene/scene.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <string>

namespace accelviz::procedural {

/// Appends MESH to the scene and returns its index.
std::uint32_t add_mesh(Scene& scene, Mesh mesh);

/// Adds a root node that places mesh MESH with translation T, a rotation of
/// YAW radians about +y and uniform scale S, and the instance that goes with
/// it. Node and instance are appended, so instances stay in node order. The
/// rotation matrix is built from sin_cos(), not from std::sin, so that a spec
/// gives the same world-space triangles everywhere; yaw 0, scale 1 and
/// translation 0 give an exact identity.
void place_mesh(Scene& scene, std::uint32_t mesh, std::string node_name, const glm::vec3& translation = glm::vec3(0.0f),
                double yaw = 0.0, float scale = 1.0f);

/// A camera at EYE looking at TARGET with +y as the up hint.
Camera look_at(std::string name, const glm::vec3& eye, const glm::vec3& target, float yfov = 0.8f);

/// A camera looking at the centre of BOX from direction FROM (need not be
/// unit), far enough that the box's bounding sphere fills the vertical field
/// of view with a small margin.
Camera frame_box(std::string name, const Aabb& box, const glm::vec3& from, float yfov = 0.8f);

Light point_light(std::string name, const glm::vec3& position, float intensity);
Light directional_light(std::string name, const glm::vec3& direction, float intensity);

/// Bounds of a mesh's positions (object space).
Aabb mesh_bounds(const Mesh& mesh);

/// Appends an axis-aligned box (8 vertices, 12 outward-facing triangles).
void append_box(Mesh& mesh, const glm::vec3& lo, const glm::vec3& hi);

/// Appends a horizontal rectangle [lo.x, hi.x] x [lo.y, hi.y] in x/z at height
/// Y as two upward-facing triangles (lo and hi are x/z pairs).
void append_ground(Mesh& mesh, const glm::vec2& lo, const glm::vec2& hi, float y = 0.0f);

/// Sets every node as a root, flattens, and records the spec as the source.
void finish(Scene& scene, const BuiltinArgs& args);

}  // namespace accelviz::procedural
