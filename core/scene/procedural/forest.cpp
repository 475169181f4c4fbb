// builtin:forest — instancing: one tree mesh placed many times with random
// position, rotation about +y and uniform scale, on a ground square. A
// two-level structure (a top-level BVH over instance boxes, a bottom-level
// one over the tree) stores the tree once; the flattened triangle list holds
// every copy. The lecture compares the two in memory and build time.
#include "core/scene/procedural/reproducible_fp.h"  // first: see there

#include "core/scene/procedural/common.h"
#include "core/scene/procedural/generators.h"
#include "core/scene/procedural/random.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace accelviz::procedural {

namespace {

constexpr int kSegments = 12;            // around trunk and crowns
constexpr double kTreeSpacing = 3.5;     // mean distance between trees: the ground grows with size
constexpr float kMinScale = 0.7f;
constexpr float kMaxScale = 1.3f;

struct Crown {
  float base;    // height of the cone's base
  float radius;  // base radius
  float height;  // apex above the base
};
constexpr Crown kCrowns[] = {{1.5f, 1.6f, 2.6f}, {2.8f, 1.25f, 2.2f}, {3.9f, 0.9f, 1.9f}};
constexpr float kTrunkRadius = 0.25f;
constexpr float kTrunkHeight = 2.0f;

/// The tree: an open trunk cylinder (its ends are hidden in the ground and
/// the crown) and three stacked cones with closed bases. Outward winding.
/// 2 * kSegments + 3 * 2 * kSegments = 96 triangles.
Mesh make_tree() {
  Mesh mesh;
  mesh.name = "tree";
  glm::vec2 ring[kSegments];
  for (int i = 0; i < kSegments; ++i) {
    const SinCos a = sin_cos(2.0 * kPi * i / kSegments);
    ring[i] = glm::vec2(static_cast<float>(a.cos), static_cast<float>(a.sin));
  }
  const auto at = [&](int i, float radius, float y) {
    return glm::vec3(radius * ring[i % kSegments].x, y, radius * ring[i % kSegments].y);
  };
  // Trunk: ring at the bottom (0..11), ring at the top (12..23).
  for (int i = 0; i < kSegments; ++i) mesh.positions.push_back(at(i, kTrunkRadius, 0.0f));
  for (int i = 0; i < kSegments; ++i) mesh.positions.push_back(at(i, kTrunkRadius, kTrunkHeight));
  for (int i = 0; i < kSegments; ++i) {
    const std::uint32_t i1 = (i + 1) % kSegments;
    // Around +y the ring runs from +x towards +z; (bottom i, top i, top i+1) faces out.
    mesh.indices.emplace_back(i, kSegments + i, kSegments + i1);
    mesh.indices.emplace_back(i, kSegments + i1, i1);
  }
  for (const Crown& crown : kCrowns) {
    const auto base = static_cast<std::uint32_t>(mesh.positions.size());
    for (int i = 0; i < kSegments; ++i) mesh.positions.push_back(at(i, crown.radius, crown.base));
    const std::uint32_t apex = base + kSegments;
    const std::uint32_t centre = apex + 1;
    mesh.positions.emplace_back(0.0f, crown.base + crown.height, 0.0f);
    mesh.positions.emplace_back(0.0f, crown.base, 0.0f);
    for (int i = 0; i < kSegments; ++i) {
      const std::uint32_t a = base + i, b = base + (i + 1) % kSegments;
      mesh.indices.emplace_back(a, apex, b);    // side, facing out and up
      mesh.indices.emplace_back(a, b, centre);  // base disc, facing down
    }
  }
  return mesh;
}

}  // namespace

Scene make_forest(const BuiltinArgs& args) {
  SplitMix64 rng(args.seed);
  const std::int64_t trees = std::max<std::int64_t>(
      1, (args.size + kForestTreeTriangles / 2) / kForestTreeTriangles);
  const float side = static_cast<float>(kTreeSpacing * std::sqrt(static_cast<double>(trees)));
  const float half = 0.5f * side;

  Scene scene;
  const std::uint32_t tree = add_mesh(scene, make_tree());
  Mesh ground;
  ground.name = "ground";
  append_ground(ground, glm::vec2(-half), glm::vec2(half));
  place_mesh(scene, add_mesh(scene, std::move(ground)), "ground");

  scene.nodes.reserve(static_cast<std::size_t>(trees) + 1);
  scene.instances.reserve(static_cast<std::size_t>(trees) + 1);
  for (std::int64_t i = 0; i < trees; ++i) {
    const glm::vec2 xz = rng.uniform2(-half, half);
    const glm::vec3 position(xz.x, 0.0f, xz.y);
    const double yaw = 2.0 * kPi * rng.uniform_double();
    const float scale = rng.uniform(kMinScale, kMaxScale);
    place_mesh(scene, tree, "tree " + std::to_string(i), position, yaw, scale);
  }

  // From just outside one edge, above the canopy, looking across the forest.
  const float canopy = kCrowns[2].base + kCrowns[2].height;
  scene.cameras.push_back(look_at("edge", glm::vec3(0.0f, 2.0f * canopy + 0.1f * side, half + 2.0f * canopy),
                                  glm::vec3(0.0f, 0.0f, 0.1f * side)));
  scene.lights.push_back(directional_light("sun", glm::vec3(-0.4f, -1.0f, -0.4f), 3.0f));
  finish(scene, args);
  return scene;
}

}  // namespace accelviz::procedural
