// Degenerate inputs for builders: scenes where the usual split heuristics
// have nothing to split on. A builder must terminate on each of them, keep
// every primitive, and not build a deep chain of one-primitive nodes.
//   same-centroid  every vertex average is the same point; the bounding
//                  boxes' centres differ (a BVH binning box centres still
//                  splits), but every box holds that point: boxes overlap
//                  there, and spatial splits copy references.
//   same-bounds    every triangle has the same bounding box: no split of
//                  boxes separates anything.
//   duplicates     one triangle N times: both of the above, and equal keys
//                  for any sort.
//   flat-wall      every triangle in the plane z = 0: zero extent on one
//                  axis (zero-volume boxes; half-area SAH still works).
#include "core/scene/procedural/reproducible_fp.h"  // first: see there

#include "core/scene/procedural/common.h"
#include "core/scene/procedural/generators.h"
#include "core/scene/procedural/random.h"

#include <cmath>

namespace accelviz::procedural {

namespace {

/// A scene with one mesh, one identity instance and a camera framing it.
Scene single_mesh_scene(Mesh mesh, const glm::vec3& view_from, const BuiltinArgs& args) {
  Scene scene;
  const Aabb box = mesh_bounds(mesh);
  place_mesh(scene, add_mesh(scene, std::move(mesh)), args.name);
  scene.cameras.push_back(frame_box("view", box, view_from));
  finish(scene, args);
  return scene;
}

}  // namespace

Scene make_same_centroid(const BuiltinArgs& args) {
  // Every coordinate is a multiple of 2^-15 below 8 in magnitude, so all sums
  // of vertices are exact in float: v0 + v1 + v2 is exactly 3c for every
  // triangle, and the centroid (v0 + v1 + v2) * (1/3) is the same float
  // vector for all of them, not merely close.
  const glm::vec3 centre(0.5f, 0.25f, -0.75f);
  SplitMix64 rng(args.seed);
  Mesh mesh;
  mesh.name = "same-centroid";
  mesh.positions.reserve(static_cast<std::size_t>(args.size) * 3);
  mesh.indices.reserve(static_cast<std::size_t>(args.size));
  for (std::int64_t i = 0; i < args.size; ++i) {
    // Two random lattice offsets in [-1024, 1024]^3; the third makes them sum to zero.
    glm::i64vec3 a, b;
    do {
      for (int k = 0; k < 3; ++k) {
        a[k] = static_cast<std::int64_t>(rng.below(2049)) - 1024;
        b[k] = static_cast<std::int64_t>(rng.below(2049)) - 1024;
      }
    } while (a.y * b.z - a.z * b.y == 0 && a.z * b.x - a.x * b.z == 0 && a.x * b.y - a.y * b.x == 0);
    // Sizes over two orders of magnitude: unit 2^-9 .. 2^-15.
    const float unit = std::ldexp(1.0f, -9 - static_cast<int>(rng.below(7)));
    const glm::vec3 da = glm::vec3(a) * unit, db = glm::vec3(b) * unit;
    const auto base = static_cast<std::uint32_t>(mesh.positions.size());
    mesh.positions.push_back(centre + da);
    mesh.positions.push_back(centre + db);
    mesh.positions.push_back(centre - (da + db));
    mesh.indices.emplace_back(base, base + 1, base + 2);
  }
  return single_mesh_scene(std::move(mesh), glm::vec3(0.4f, 0.5f, 1.0f), args);
}

Scene make_same_bounds(const BuiltinArgs& args) {
  // Box [lo, hi]. A triangle's box is exactly this one when, on every axis,
  // one vertex sits at lo, another at hi and the third anywhere between.
  // Which vertex takes which role rotates with the axis; the axis order and
  // which end each role takes are drawn per triangle, and the free
  // coordinates are random, so the triangles are distinct.
  const glm::vec3 lo(-1.0f, -0.5f, -2.0f), hi(1.0f, 0.5f, 2.0f);
  static constexpr int kPermutations[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  SplitMix64 rng(args.seed);
  Mesh mesh;
  mesh.name = "same-bounds";
  mesh.positions.reserve(static_cast<std::size_t>(args.size) * 3);
  mesh.indices.reserve(static_cast<std::size_t>(args.size));
  for (std::int64_t i = 0; i < args.size; ++i) {
    glm::vec3 v[3];
    const int* axes = kPermutations[rng.below(6)];
    for (int slot = 0; slot < 3; ++slot) {
      const int axis = axes[slot];
      const bool flip = (rng.next() >> 63) != 0;
      v[slot][axis] = flip ? hi[axis] : lo[axis];
      v[(slot + 1) % 3][axis] = flip ? lo[axis] : hi[axis];
      v[(slot + 2) % 3][axis] = rng.uniform(lo[axis], hi[axis]);
    }
    const auto base = static_cast<std::uint32_t>(mesh.positions.size());
    for (const glm::vec3& p : v) mesh.positions.push_back(p);
    mesh.indices.emplace_back(base, base + 1, base + 2);
  }
  return single_mesh_scene(std::move(mesh), glm::vec3(0.5f, 0.6f, 1.0f), args);
}

Scene make_duplicates(const BuiltinArgs& args) {
  // One seeded, well-shaped triangle; N index triples that all name it.
  SplitMix64 rng(args.seed);
  Mesh mesh;
  mesh.name = "duplicates";
  const glm::vec3 corner = rng.uniform3(-1.0f, 1.0f);
  // Edge along roughly +x, then one along roughly +y (one draw per statement:
  // see SplitMix64::uniform2).
  glm::vec3 e1(0.0f), e2(0.0f);
  e1.x = rng.uniform(0.5f, 1.0f);
  e1.y = rng.uniform(-0.2f, 0.2f);
  e2.x = rng.uniform(-0.2f, 0.2f);
  e2.y = rng.uniform(0.5f, 1.0f);
  e2.z = rng.uniform(-0.2f, 0.2f);
  mesh.positions.push_back(corner);
  mesh.positions.push_back(corner + e1);
  mesh.positions.push_back(corner + e2);
  mesh.indices.assign(static_cast<std::size_t>(args.size), glm::uvec3(0, 1, 2));
  return single_mesh_scene(std::move(mesh), glm::vec3(0.3f, 0.3f, 1.0f), args);
}

Scene make_flat_wall(const BuiltinArgs& args) {
  // Random triangles in the unit square of the plane z = 0 (a wall facing +z),
  // sized ~ N^(-1/2) for constant density, like a 2D soup.
  SplitMix64 rng(args.seed);
  const float radius = static_cast<float>(0.5 / std::sqrt(static_cast<double>(args.size)));
  Mesh mesh;
  mesh.name = "flat-wall";
  mesh.positions.reserve(static_cast<std::size_t>(args.size) * 3);
  mesh.indices.reserve(static_cast<std::size_t>(args.size));
  for (std::int64_t i = 0; i < args.size; ++i) {
    const glm::vec2 centre = rng.uniform2(radius, 1.0f - radius);
    glm::vec3 v[3];
    do {
      for (glm::vec3& p : v) {
        glm::vec2 d;
        float r2;
        do {
          d = rng.uniform2(-1.0f, 1.0f);
          r2 = glm::dot(d, d);
        } while (r2 <= 0.01f || r2 > 1.0f);
        p = glm::vec3(glm::clamp(centre + (radius / std::sqrt(r2)) * d, 0.0f, 1.0f), 0.0f);
      }
    } while (is_sliver(v, radius));  // as in soup: no zero-area needles
    const auto base = static_cast<std::uint32_t>(mesh.positions.size());
    for (const glm::vec3& p : v) mesh.positions.push_back(p);
    mesh.indices.emplace_back(base, base + 1, base + 2);
  }
  return single_mesh_scene(std::move(mesh), glm::vec3(0.2f, 0.1f, 1.0f), args);
}

}  // namespace accelviz::procedural
