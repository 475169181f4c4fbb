// builtin:soup — N random triangles in the unit cube: random centres, random
// orientations and shapes, size ~ N^(-1/3) so that the density (triangles per
// volume, and the overlap between neighbours) stays the same at every N.
// The structureless baseline against which the other scenes are compared.
#include "core/scene/procedural/reproducible_fp.h"  // first: see there

#include "core/scene/procedural/common.h"
#include "core/scene/procedural/generators.h"
#include "core/scene/procedural/random.h"

#include <cmath>

namespace accelviz::procedural {

namespace {

/// A uniformly random unit vector (rejection from the ball; basic operations
/// and sqrt only, so the same everywhere).
glm::vec3 random_unit(SplitMix64& rng) {
  while (true) {
    const glm::vec3 v = rng.uniform3(-1.0f, 1.0f);
    const float r2 = glm::dot(v, v);
    if (r2 > 0.01f && r2 <= 1.0f) return v / std::sqrt(r2);
  }
}

}  // namespace

bool is_sliver(const glm::vec3 (&v)[3], float radius) {
  // Twice the area, in double from the float vertices (what flatten() tests
  // for zero), against the largest possible (3 sqrt(3)/2 r^2 for an
  // equilateral triangle): below 1e-4 of it the shape is a needle whose area
  // rounds to nothing at large N. Redrawing those keeps the soup free of
  // zero-area triangles; it removes a negligible part of the distribution.
  const glm::dvec3 a(v[0]), b(v[1]), c(v[2]);
  const glm::dvec3 n = glm::cross(b - a, c - a);
  const double r2 = static_cast<double>(radius) * radius;
  return glm::dot(n, n) < 1e-8 * 6.75 * r2 * r2;
}

Scene make_soup(const BuiltinArgs& args) {
  SplitMix64 rng(args.seed);
  const std::int64_t count = args.size;
  // Vertices lie on a sphere of this radius about the centre, so edges are
  // up to 2 r = N^(-1/3) long, and centres stay r inside the cube so that
  // every vertex is inside it.
  const float radius = static_cast<float>(0.5 / cbrt_positive(static_cast<double>(count)));

  Mesh mesh;
  mesh.name = "soup";
  mesh.positions.reserve(static_cast<std::size_t>(count) * 3);
  mesh.indices.reserve(static_cast<std::size_t>(count));
  for (std::int64_t i = 0; i < count; ++i) {
    const glm::vec3 centre = rng.uniform3(radius, 1.0f - radius);
    glm::vec3 v[3];
    do {
      for (glm::vec3& p : v) p = glm::clamp(centre + radius * random_unit(rng), 0.0f, 1.0f);
    } while (is_sliver(v, radius));
    const auto base = static_cast<std::uint32_t>(mesh.positions.size());
    for (const glm::vec3& p : v) mesh.positions.push_back(p);
    mesh.indices.emplace_back(base, base + 1, base + 2);
  }

  Scene scene;
  place_mesh(scene, add_mesh(scene, std::move(mesh)), "soup");
  scene.cameras.push_back(frame_box("outside", Aabb{glm::vec3(0.0f), glm::vec3(1.0f)}, glm::vec3(1.0f, 0.8f, 1.3f)));
  scene.lights.push_back(directional_light("sun", glm::vec3(-0.3f, -1.0f, -0.5f), 3.0f));
  finish(scene, args);
  return scene;
}

}  // namespace accelviz::procedural
