// builtin:grass — a lawn: many long, thin, overlapping triangles of similar
// size spread uniformly over a ground square. Every blade's box overlaps many
// neighbours', so spatial splits and SAH quality matter more than in
// scenes of compact triangles.
#include "core/scene/procedural/reproducible_fp.h"  // first: see there

#include "core/scene/procedural/common.h"
#include "core/scene/procedural/generators.h"
#include "core/scene/procedural/random.h"

#include <algorithm>
#include <cmath>

namespace accelviz::procedural {

namespace {

constexpr int kTrianglesPerBlade = 3;   // a two-segment quad strip and a tip
constexpr double kBladesPerArea = 200;  // per square unit: the field grows with size
constexpr float kMinHeight = 0.08f;
constexpr float kMaxHeight = 0.3f;
constexpr float kMinHalfWidth = 0.004f;
constexpr float kMaxHalfWidth = 0.009f;
constexpr float kMaxLean = 0.4f;  // tip's horizontal offset / height

/// A uniformly random unit vector in the x/z plane (rejection from the disc:
/// only basic operations and sqrt, so the result is the same everywhere).
glm::vec2 random_direction(SplitMix64& rng) {
  while (true) {
    const float a = rng.uniform(-1.0f, 1.0f);
    const float b = rng.uniform(-1.0f, 1.0f);
    const float r2 = a * a + b * b;
    if (r2 > 0.01f && r2 <= 1.0f) return glm::vec2(a, b) / std::sqrt(r2);
  }
}

}  // namespace

Scene make_grass(const BuiltinArgs& args) {
  SplitMix64 rng(args.seed);
  const std::int64_t blades = std::max<std::int64_t>(1, (args.size + 1) / kTrianglesPerBlade);
  const float side = static_cast<float>(std::max(1.0, std::sqrt(static_cast<double>(blades) / kBladesPerArea)));
  const float half = 0.5f * side;

  Mesh grass;
  grass.name = "grass";
  grass.positions.reserve(static_cast<std::size_t>(blades) * 5);
  grass.indices.reserve(static_cast<std::size_t>(blades) * kTrianglesPerBlade);
  for (std::int64_t i = 0; i < blades; ++i) {
    const glm::vec2 xz = rng.uniform2(-half, half);
    const glm::vec3 root(xz.x, 0.0f, xz.y);
    const float height = rng.uniform(kMinHeight, kMaxHeight);
    const float half_width = rng.uniform(kMinHalfWidth, kMaxHalfWidth);
    const glm::vec2 facing = random_direction(rng);           // across the blade
    const float lean = rng.uniform(-kMaxLean, kMaxLean) * height;  // along the blade normal
    const glm::vec3 across(facing.x, 0.0f, facing.y);
    const glm::vec3 bend(-facing.y, 0.0f, facing.x);
    // Parabolic bend: offset lean * t^2 at height fraction t; the blade's
    // vertical reach shrinks so that its length stays about `height`.
    const float reach = std::sqrt(height * height - 0.5f * lean * lean);
    const auto spine = [&](float t) { return root + glm::vec3(0.0f, reach * t, 0.0f) + (lean * t * t) * bend; };
    const auto base = static_cast<std::uint32_t>(grass.positions.size());
    grass.positions.push_back(spine(0.0f) - half_width * across);
    grass.positions.push_back(spine(0.0f) + half_width * across);
    grass.positions.push_back(spine(0.5f) - 0.6f * half_width * across);
    grass.positions.push_back(spine(0.5f) + 0.6f * half_width * across);
    grass.positions.push_back(spine(1.0f));
    grass.indices.emplace_back(base + 0, base + 1, base + 3);
    grass.indices.emplace_back(base + 0, base + 3, base + 2);
    grass.indices.emplace_back(base + 2, base + 3, base + 4);
  }

  Mesh ground;
  ground.name = "ground";
  append_ground(ground, glm::vec2(-half), glm::vec2(half));

  Scene scene;
  place_mesh(scene, add_mesh(scene, std::move(grass)), "grass");
  place_mesh(scene, add_mesh(scene, std::move(ground)), "ground");
  // Low oblique view from one edge across the field.
  scene.cameras.push_back(look_at("field", glm::vec3(0.15f * side, 0.5f + 0.12f * side, 0.5f * side + 1.0f),
                                  glm::vec3(0.0f, 0.0f, 0.1f * side)));
  scene.lights.push_back(directional_light("sun", glm::vec3(-0.4f, -1.0f, -0.3f), 3.0f));
  finish(scene, args);
  return scene;
}

}  // namespace accelviz::procedural
