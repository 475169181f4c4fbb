#pragma once
// The Utah teapot: Martin Newell's 32 bicubic Bezier patches over 306 control
// points (Newell 1975, the public-domain Utah teapot data set; its history is
// told in Crow, "The Origins of the Teapot", IEEE CG&A 7(1), 1987),
// tessellated into a welded triangle mesh.
#include "core/scene/scene.h"

#include <glm/glm.hpp>

#include <array>
#include <cstdint>

namespace accelviz::procedural {

inline constexpr int kTeapotPatchCount = 32;
inline constexpr int kTeapotControlPointCount = 306;

/// Control points as published: z up, units of the original data (the body
/// is 4 wide and the lid knob tops out at z = 3.15).
const std::array<glm::vec3, kTeapotControlPointCount>& teapot_control_points();

/// Patch control-point indices, 0-based (the published table is 1-based),
/// row-major: patch[4 * i + j] is the point at (u = i/3, v = j/3).
const std::array<std::array<std::uint16_t, 16>, kTeapotPatchCount>& teapot_patches();

/// Triangles a tessellation at LEVEL (n x n quads per patch) produces:
/// 2 n^2 per patch, less the n zero-area triangles at each of the 8 pole
/// patches (lid knob and bottom), which are dropped: 64 n^2 - 8 n.
std::int64_t teapot_triangle_count(int level);

/// Coarsest level: at n = 1 the spout and handle tubes, two patches around,
/// collapse to flat strips (zero-area triangles, edges shared by 4).
inline constexpr int kTeapotMinLevel = 2;

/// The level whose triangle count is closest to TRIANGLES (at least
/// kTeapotMinLevel, i.e. 240 triangles).
int teapot_level_for(std::int64_t triangles);

/// Tessellates every patch on an (n+1) x (n+1) grid of equal parameter steps
/// and welds vertices at patch seams, so that neighbouring patches share
/// vertices (the mesh is watertight along seams; the teapot itself still has
/// open boundaries at the spout, the handle ends, the lid rim and the rim of
/// the pot). Output is y-up (Newell's z becomes y), outward-facing winding.
Mesh tessellate_teapot(int level);  ///< level below kTeapotMinLevel is raised to it

}  // namespace accelviz::procedural
