// builtin:teapot-stadium — Haines' "teapot in a stadium": a small, densely
// tessellated object inside a huge, sparse one. A uniform grid sized to the
// scene bounds puts the whole teapot into one or two cells, which is why the
// lecture uses it to motivate adaptive structures (octrees, BVHs, nested
// grids). The teapot holds nearly all triangles; the stadium is a bowl of
// tiers and a ground square made of few, very large triangles.
#include "core/scene/procedural/reproducible_fp.h"  // first: see there

#include "core/scene/procedural/common.h"
#include "core/scene/procedural/generators.h"
#include "core/scene/procedural/random.h"
#include "core/scene/procedural/teapot.h"

#include <algorithm>
#include <vector>

namespace accelviz::procedural {

namespace {

constexpr int kStandSegments = 32;        // around the bowl
constexpr int kStandTiers = 6;            // riser + tread steps
constexpr double kArenaFraction = 0.45;   // open arena radius / outer radius
constexpr double kHeightFraction = 0.15;  // stand height / outer diameter

/// The stands as a surface of revolution of a stepped profile: from the
/// arena edge up riser, across tread, ... to the top, then down the outer
/// wall. Faces point into the arena and up.
Mesh make_stands(double outer_radius) {
  const double inner = kArenaFraction * outer_radius;
  const double height = kHeightFraction * 2.0 * outer_radius;
  // Profile (radius, height), 2 * tiers + 2 points.
  std::vector<glm::dvec2> profile;
  profile.emplace_back(inner, 0.0);
  for (int k = 0; k < kStandTiers; ++k) {
    const double r0 = inner + (outer_radius - inner) * k / kStandTiers;
    const double r1 = k + 1 == kStandTiers ? outer_radius : inner + (outer_radius - inner) * (k + 1) / kStandTiers;
    const double h = height * (k + 1) / kStandTiers;
    profile.emplace_back(r0, h);
    profile.emplace_back(r1, h);
  }
  profile.emplace_back(outer_radius, 0.0);

  Mesh mesh;
  mesh.name = "stands";
  const int rings = static_cast<int>(profile.size());
  mesh.positions.reserve(static_cast<std::size_t>(rings) * kStandSegments);
  for (const glm::dvec2& p : profile) {
    for (int i = 0; i < kStandSegments; ++i) {
      const SinCos a = sin_cos(2.0 * kPi * i / kStandSegments);
      mesh.positions.emplace_back(static_cast<float>(p.x * a.cos), static_cast<float>(p.y),
                                  static_cast<float>(p.x * a.sin));
    }
  }
  for (int s = 0; s + 1 < rings; ++s) {
    for (int i = 0; i < kStandSegments; ++i) {
      const int i1 = (i + 1) % kStandSegments;
      const auto v = [&](int ring, int seg) { return static_cast<std::uint32_t>(ring * kStandSegments + seg); };
      // (s,i) -> (s+1,i+1) -> (s+1,i): for a riser this faces the arena, for a
      // tread it faces up, for the outer wall it faces out.
      mesh.indices.emplace_back(v(s, i), v(s + 1, i1), v(s + 1, i));
      mesh.indices.emplace_back(v(s, i), v(s, i1), v(s + 1, i1));
    }
  }
  return mesh;
}

}  // namespace

Scene make_teapot_stadium(const BuiltinArgs& args) {
  const double ratio = args.real("ratio");
  Scene scene;

  // Teapot at the centre, standing on the ground (y = 0), with every
  // triangle the stadium does not use.
  Mesh teapot = tessellate_teapot(teapot_level_for(std::max<std::int64_t>(args.size - kStadiumTriangles, 1)));
  const Aabb teapot_box = mesh_bounds(teapot);
  const glm::vec3 e = teapot_box.extent();
  const double teapot_size = std::max({e.x, e.y, e.z});

  // Stadium: outer diameter = ratio x the teapot's largest extent; the ground
  // square spans exactly that diameter, so the stadium's bounds are ratio
  // times the teapot's.
  const double outer_radius = 0.5 * ratio * teapot_size;
  Mesh stands = make_stands(outer_radius);
  Mesh ground;
  ground.name = "ground";
  const float r = static_cast<float>(outer_radius);
  append_ground(ground, glm::vec2(-r), glm::vec2(r));

  place_mesh(scene, add_mesh(scene, std::move(teapot)), "teapot");
  place_mesh(scene, add_mesh(scene, std::move(stands)), "stands");
  place_mesh(scene, add_mesh(scene, std::move(ground)), "ground");

  // Camera 0, pitch side: close to the teapot and low, so that the stands
  // rise behind it.
  const glm::vec3 centre = teapot_box.center();
  scene.cameras.push_back(frame_box("pitch-side", teapot_box, glm::vec3(0.3f, 0.12f, 1.0f)));

  // Camera 1, from the seats: front row, 60 degrees round from +x, with a
  // telephoto field of view that frames the teapot.
  const double inner = kArenaFraction * outer_radius;
  const double tier_depth = (outer_radius - inner) / kStandTiers;
  const double tier_height = kHeightFraction * 2.0 * outer_radius / kStandTiers;
  const SinCos seat_dir = sin_cos(kPi / 3.0);
  const double seat_radius = inner + 0.5 * tier_depth;
  const glm::vec3 seat(static_cast<float>(seat_radius * seat_dir.cos), static_cast<float>(1.05 * tier_height),
                       static_cast<float>(seat_radius * seat_dir.sin));
  const double seat_distance = glm::length(glm::dvec3(seat) - glm::dvec3(centre));
  const double teapot_radius = 0.5 * glm::length(glm::dvec3(e));
  const float seat_fov = static_cast<float>(2.0 * atan_nonnegative(1.2 * teapot_radius / seat_distance));
  scene.cameras.push_back(look_at("seats", seat, centre, seat_fov));

  // Camera 2, aerial: the whole bowl (the teapot is a speck).
  Aabb stadium_box = mesh_bounds(scene.meshes[1]);
  stadium_box.extend(mesh_bounds(scene.meshes[2]));
  scene.cameras.push_back(frame_box("aerial", stadium_box, glm::vec3(0.3f, 0.8f, 1.0f)));

  // One point light over the arena, as high as the stands, off to the front
  // right of the teapot; intensity ~ distance^2 for an irradiance of about 1
  // at the teapot.
  const float stand_height = static_cast<float>(kHeightFraction * 2.0 * outer_radius);
  const glm::vec3 light_pos(0.3f * static_cast<float>(inner), stand_height, 0.4f * static_cast<float>(inner));
  const glm::vec3 to_teapot = light_pos - centre;
  scene.lights.push_back(point_light("floodlight", light_pos, glm::dot(to_teapot, to_teapot)));

  finish(scene, args);
  return scene;
}

}  // namespace accelviz::procedural
