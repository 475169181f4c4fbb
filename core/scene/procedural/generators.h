#pragma once
// One generator per built-in scene (one file each); builtin.cpp maps names
// to them. Each takes validated arguments and returns a flattened Scene
// whose source is the spec.
#include "core/scene/procedural/spec.h"
#include "core/scene/scene.h"

#include <glm/glm.hpp>

#include <cstdint>

namespace accelviz::procedural {

Scene make_teapot(const BuiltinArgs& args);          // teapot.cpp
Scene make_teapot_stadium(const BuiltinArgs& args);  // teapot_stadium.cpp
Scene make_grass(const BuiltinArgs& args);           // grass.cpp
Scene make_terrain(const BuiltinArgs& args);         // terrain.cpp
Scene make_soup(const BuiltinArgs& args);            // soup.cpp
Scene make_walls(const BuiltinArgs& args);           // walls.cpp ("walls" and "walls-rotated")
Scene make_forest(const BuiltinArgs& args);          // forest.cpp
Scene make_island(const BuiltinArgs& args);          // island.cpp
Scene make_dynamic(const BuiltinArgs& args);         // dynamic.cpp
Scene make_same_centroid(const BuiltinArgs& args);   // degenerate.cpp
Scene make_same_bounds(const BuiltinArgs& args);     // degenerate.cpp
Scene make_duplicates(const BuiltinArgs& args);      // degenerate.cpp
Scene make_flat_wall(const BuiltinArgs& args);       // degenerate.cpp

/// True when the triangle V (vertices about `radius` from its centre) is so
/// thin that its area is below 1e-4 of the largest such triangle's (soup.cpp).
bool is_sliver(const glm::vec3 (&v)[3], float radius);

/// Triangles in the stadium part of teapot-stadium (stands and ground); the
/// teapot gets the rest of `size`.
inline constexpr std::int64_t kStadiumTriangles = 834;

/// Island: most unique triangles `size` may ask for, and the instanced
/// triangle count above which the scene is left unflattened (tlas only).
inline constexpr std::int64_t kIslandMaxUnique = 10'000'000;
inline constexpr std::int64_t kIslandFlattenLimit = 50'000'000;

/// Triangles in one forest tree (trunk and crowns).
inline constexpr std::int64_t kForestTreeTriangles = 96;

}  // namespace accelviz::procedural
