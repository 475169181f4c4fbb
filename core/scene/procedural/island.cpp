// builtin:island — a Moana-like island: a height-field island and eight
// plant species (palms, bushes, rocks: a trunk and a noisy crown each), every
// species instanced `copies` times over the island. `size` counts the UNIQUE
// triangles (at most 10,000,000); the world holds about
// 0.1 size + 0.9 size copies of them. Above 50,000,000 instanced triangles
// the scene is not flattened (Scene::triangles stays empty, a load warning
// says so): only the two-level structure ("tlas") holds it, which is the
// point of the lecture's Moana figures (15 billion instanced from ~90
// million unique).
#include <algorithm>
#include <cmath>
#include <string>

#include "core/scene/procedural/common.h"
#include "core/scene/procedural/generators.h"
#include "core/scene/procedural/random.h"
#include "core/scene/procedural/reproducible_fp.h"  // first: see there

namespace accelviz::procedural {

namespace {

constexpr int kSpecies = 8;
constexpr double kPlantSpacing = 4.0;  // mean distance between plants: the island grows with the count

struct Species {
  float trunk_height, trunk_radius;
  glm::vec3 crown_radius;  // ellipsoid semi-axes
  float bumpiness;         // relative radial noise of the crown
};
constexpr Species kSpeciesShape[kSpecies] = {
    {6.0f, 0.25f, {2.6f, 0.9f, 2.6f}, 0.25f},  // palms
    {5.0f, 0.22f, {2.2f, 0.8f, 2.2f}, 0.30f}, {7.0f, 0.28f, {3.0f, 1.0f, 3.0f}, 0.20f},
    {4.0f, 0.20f, {1.8f, 0.7f, 1.8f}, 0.35f}, {0.6f, 0.15f, {1.5f, 1.2f, 1.5f}, 0.15f},  // bushes
    {0.4f, 0.12f, {1.1f, 0.9f, 1.1f}, 0.20f}, {0.3f, 0.50f, {1.4f, 0.8f, 1.2f}, 0.10f},  // rocks
    {0.3f, 0.60f, {2.0f, 1.0f, 1.6f}, 0.12f},
};

/// A plant of about BUDGET triangles: an open trunk cylinder (8 sides,
/// a quarter of the budget) and a UV ellipsoid crown with smooth radial
/// bumps (the rest), sitting on top of the trunk.
Mesh make_plant(int species, std::int64_t budget, SplitMix64& rng) {
  const Species& sp = kSpeciesShape[species];
  Mesh mesh;
  mesh.name = "plant " + std::to_string(species);
  constexpr int kSides = 8;
  const std::int64_t rings = std::max<std::int64_t>(1, budget / 4 / (2 * kSides));
  for (std::int64_t r = 0; r <= rings; ++r) {
    const float y = sp.trunk_height * static_cast<float>(r) / static_cast<float>(rings);
    for (int i = 0; i < kSides; ++i) {
      const SinCos a = sin_cos(2.0 * kPi * i / kSides);
      mesh.positions.emplace_back(sp.trunk_radius * static_cast<float>(a.cos), y,
                                  sp.trunk_radius * static_cast<float>(a.sin));
    }
  }
  for (std::int64_t r = 0; r < rings; ++r)
    for (int i = 0; i < kSides; ++i) {
      const auto a = static_cast<std::uint32_t>(r * kSides + i);
      const auto b = static_cast<std::uint32_t>(r * kSides + (i + 1) % kSides);
      mesh.indices.emplace_back(a, a + kSides, b + kSides);
      mesh.indices.emplace_back(a, b + kSides, b);
    }
  // Crown: L latitude bands, M = 2 (L - 1) meridians: 2 M (L - 1) = 4 (L-1)^2 triangles.
  const std::int64_t crown_budget = std::max<std::int64_t>(24, budget - static_cast<std::int64_t>(mesh.indices.size()));
  const std::int64_t l1 = std::max<std::int64_t>(2, std::llround(std::sqrt(static_cast<double>(crown_budget) / 4.0)));
  const std::int64_t bands = l1 + 1, meridians = 2 * l1;
  const double f1 = 2.0 + std::floor(4.0 * rng.uniform_double()), f2 = 3.0 + std::floor(4.0 * rng.uniform_double());
  const double p1 = 2.0 * kPi * rng.uniform_double(), p2 = 2.0 * kPi * rng.uniform_double();
  const glm::vec3 centre(0.0f, sp.trunk_height + 0.6f * sp.crown_radius.y, 0.0f);
  const auto base = static_cast<std::uint32_t>(mesh.positions.size());
  mesh.positions.push_back(centre + glm::vec3(0.0f, sp.crown_radius.y, 0.0f));  // north pole
  for (std::int64_t b = 1; b < bands; ++b) {
    const SinCos lat = sin_cos(kPi * static_cast<double>(b) / static_cast<double>(bands));
    for (std::int64_t m = 0; m < meridians; ++m) {
      const double lon = 2.0 * kPi * static_cast<double>(m) / static_cast<double>(meridians);
      const SinCos lo = sin_cos(lon);
      const double bump = 1.0 + sp.bumpiness * sin_cos(f1 * lon + p1).sin * sin_cos(f2 * kPi * b / bands + p2).cos;
      mesh.positions.push_back(centre + glm::vec3(static_cast<float>(bump * lat.sin * lo.cos) * sp.crown_radius.x,
                                                  static_cast<float>(bump * lat.cos) * sp.crown_radius.y,
                                                  static_cast<float>(bump * lat.sin * lo.sin) * sp.crown_radius.z));
    }
  }
  const auto south = static_cast<std::uint32_t>(mesh.positions.size());
  mesh.positions.push_back(centre - glm::vec3(0.0f, sp.crown_radius.y, 0.0f));
  const auto ring = [&](std::int64_t b, std::int64_t m) {
    return base + 1 + static_cast<std::uint32_t>((b - 1) * meridians + (m % meridians));
  };
  for (std::int64_t m = 0; m < meridians; ++m) {
    mesh.indices.emplace_back(base, ring(1, m + 1), ring(1, m));
    for (std::int64_t b = 1; b + 1 < bands; ++b) {
      mesh.indices.emplace_back(ring(b, m), ring(b, m + 1), ring(b + 1, m + 1));
      mesh.indices.emplace_back(ring(b, m), ring(b + 1, m + 1), ring(b + 1, m));
    }
    mesh.indices.emplace_back(south, ring(bands - 1, m), ring(bands - 1, m + 1));
  }
  return mesh;
}

/// Island height at (x, z) for an island of radius R: a dome with ripples,
/// dipping under the sea (y < 0) near the shore.
double island_height(double x, double z, double radius) {
  const double r2 = (x * x + z * z) / (radius * radius);
  const double ripple = sin_cos(0.21 * x + 0.4).sin * sin_cos(0.17 * z + 1.3).cos;
  return 0.08 * radius * (1.0 - r2) * (1.0 + 0.3 * ripple) - 1.0;
}

}  // namespace

Scene make_island(const BuiltinArgs& args) {
  if (args.size > kIslandMaxUnique)
    spec_error(args.name, "size=" + std::to_string(args.size) + " is too large: at most " +
                              std::to_string(kIslandMaxUnique) + " unique triangles");
  const auto copies = static_cast<std::int64_t>(std::llround(args.real("copies")));
  SplitMix64 rng(args.seed);
  const std::int64_t ground_budget = std::max<std::int64_t>(2, args.size / 10);
  const std::int64_t n = std::max<std::int64_t>(1, std::llround(std::sqrt(static_cast<double>(ground_budget) / 2.0)));
  const std::int64_t plant_budget = std::max<std::int64_t>(48, (args.size - 2 * n * n) / kSpecies);
  const std::int64_t plants = copies * kSpecies;
  const double radius = std::max(20.0, kPlantSpacing * std::sqrt(static_cast<double>(plants) / kPi) / 0.8);

  Scene scene;
  Mesh ground;
  ground.name = "island";
  const std::int64_t side = n + 1;
  for (std::int64_t i = 0; i <= n; ++i) {
    const double x = -radius + 2.0 * radius * static_cast<double>(i) / static_cast<double>(n);
    for (std::int64_t j = 0; j <= n; ++j) {
      const double z = -radius + 2.0 * radius * static_cast<double>(j) / static_cast<double>(n);
      ground.positions.emplace_back(static_cast<float>(x), static_cast<float>(island_height(x, z, radius)),
                                    static_cast<float>(z));
    }
  }
  for (std::int64_t i = 0; i < n; ++i)
    for (std::int64_t j = 0; j < n; ++j) {
      const auto a = static_cast<std::uint32_t>(i * side + j);
      ground.indices.emplace_back(a, a + 1, a + side + 1);
      ground.indices.emplace_back(a, a + side + 1, a + side);
    }
  place_mesh(scene, add_mesh(scene, std::move(ground)), "island");
  std::uint32_t species_mesh[kSpecies];
  for (int s = 0; s < kSpecies; ++s) species_mesh[s] = add_mesh(scene, make_plant(s, plant_budget, rng));

  scene.nodes.reserve(static_cast<std::size_t>(plants) + 1);
  scene.instances.reserve(static_cast<std::size_t>(plants) + 1);
  for (std::int64_t i = 0; i < plants; ++i) {
    // Uniform in the disc of 0.8 R (rejection, fixed draw order).
    glm::vec2 xz;
    do {
      xz = rng.uniform2(-0.8f, 0.8f);
    } while (xz.x * xz.x + xz.y * xz.y > 0.64f);
    xz *= static_cast<float>(radius);
    const auto y = static_cast<float>(island_height(xz.x, xz.y, radius)) - 0.2f;
    const double yaw = 2.0 * kPi * rng.uniform_double();
    const float scale = rng.uniform(0.6f, 1.4f);
    const int s = static_cast<int>(i % kSpecies);
    place_mesh(scene, species_mesh[s], "plant " + std::to_string(i), glm::vec3(xz.x, y, xz.y), yaw, scale);
  }

  const auto r = static_cast<float>(radius);
  const Aabb box{glm::vec3(-r, -1.0f, -r), glm::vec3(r, 0.08f * r + 10.0f, r)};
  // Default camera: on the beach, looking across the plants at the island's top.
  const double shore = 0.75 * radius;
  const auto eye_y = static_cast<float>(island_height(0.0, shore, radius)) + 5.0f;
  scene.cameras.push_back(
      look_at("beach", glm::vec3(0.0f, eye_y, static_cast<float>(shore)), glm::vec3(0.0f, 0.04f * r, 0.0f)));
  scene.cameras.push_back(frame_box("overview", box, glm::vec3(0.6f, 0.45f, 1.0f)));
  scene.lights.push_back(directional_light("sun", glm::vec3(-0.4f, -1.0f, -0.3f), 3.0f));

  const std::uint64_t instanced = scene.instanced_triangle_count();
  if (instanced <= static_cast<std::uint64_t>(kIslandFlattenLimit)) {
    finish(scene, args);
  } else {
    scene.source = args.source;
    scene.roots.clear();
    for (std::size_t i = 0; i < scene.nodes.size(); ++i) scene.roots.push_back(static_cast<int>(i));
    scene.report.warnings.push_back(args.source + ": " + std::to_string(instanced) +
                                    " instanced triangles, not flattened (over " + std::to_string(kIslandFlattenLimit) +
                                    "): only the two-level structure 'tlas' can hold it");
  }
  return scene;
}

}  // namespace accelviz::procedural
