// builtin:walls and builtin:walls-rotated — a floor plan of k x k square
// rooms whose walls are long, thin boxes with a doorway in every wall.
// Axis-aligned, every wall's bounding box is tight; rotated by `angle` about
// the vertical axis, the same walls get boxes that are mostly empty (a 4 x
// 0.1 wall at 45 degrees has a 2.9 x 2.9 box), which is the lecture's case
// for oriented or spatial-split structures (Stich et al. 2009, SBVH). The
// rotation is the placing node's transform, so the mesh itself stays
// axis-aligned in object space.
#include "core/scene/procedural/reproducible_fp.h"  // first: see there

#include "core/scene/procedural/common.h"
#include "core/scene/procedural/generators.h"
#include "core/scene/procedural/random.h"

#include <algorithm>
#include <cmath>

namespace accelviz::procedural {

namespace {

constexpr float kRoom = 4.0f;        // room side
constexpr float kThickness = 0.1f;   // wall thickness
constexpr float kHeight = 2.5f;      // wall height
constexpr float kDoor = 1.0f;        // doorway width
constexpr float kDoorMargin = 0.75f;  // doorway centre kept this far from a room corner
constexpr std::int64_t kTrianglesPerBox = 12;

/// Boxes in a k x k plan: each of the k+1 lines along x is one wall broken by
/// k doorways (k+1 boxes); each of the k+1 lines along z has 2 boxes per room
/// edge, fitted between the x lines.
std::int64_t box_count(std::int64_t k) { return (k + 1) * (k + 1) + 2 * k * (k + 1); }

}  // namespace

Scene make_walls(const BuiltinArgs& args) {
  SplitMix64 rng(args.seed);
  // Rooms per side whose triangle count is closest to size.
  std::int64_t k = std::max<std::int64_t>(1, std::llround(std::sqrt(static_cast<double>(args.size) / 36.0)));
  while (k > 1 && std::llabs(kTrianglesPerBox * box_count(k - 1) - args.size) <=
                      std::llabs(kTrianglesPerBox * box_count(k) - args.size))
    --k;
  while (std::llabs(kTrianglesPerBox * box_count(k + 1) - args.size) <
         std::llabs(kTrianglesPerBox * box_count(k) - args.size))
    ++k;

  const float span = kRoom * static_cast<float>(k);  // wall centre lines run from 0 to span
  const float t = 0.5f * kThickness;
  const float shift = -0.5f * span;  // centre the plan on the origin
  const auto line = [&](std::int64_t i) { return shift + kRoom * static_cast<float>(i); };
  const auto door_centre = [&](float start) { return start + rng.uniform(kDoorMargin, kRoom - kDoorMargin); };

  Mesh mesh;
  mesh.name = "walls";
  mesh.positions.reserve(static_cast<std::size_t>(box_count(k)) * 8);
  mesh.indices.reserve(static_cast<std::size_t>(box_count(k)) * kTrianglesPerBox);
  // Walls along x at z = line(j): full length including the corner posts.
  for (std::int64_t j = 0; j <= k; ++j) {
    const float z = line(j);
    float from = line(0) - t;
    for (std::int64_t i = 0; i < k; ++i) {
      const float door = door_centre(line(i));
      append_box(mesh, glm::vec3(from, 0.0f, z - t), glm::vec3(door - 0.5f * kDoor, kHeight, z + t));
      from = door + 0.5f * kDoor;
    }
    append_box(mesh, glm::vec3(from, 0.0f, z - t), glm::vec3(line(k) + t, kHeight, z + t));
  }
  // Walls along z at x = line(i), between the x walls, one doorway per room edge.
  for (std::int64_t i = 0; i <= k; ++i) {
    const float x = line(i);
    for (std::int64_t j = 0; j < k; ++j) {
      const float door = door_centre(line(j));
      append_box(mesh, glm::vec3(x - t, 0.0f, line(j) + t), glm::vec3(x + t, kHeight, door - 0.5f * kDoor));
      append_box(mesh, glm::vec3(x - t, 0.0f, door + 0.5f * kDoor), glm::vec3(x + t, kHeight, line(j + 1) - t));
    }
  }

  Scene scene;
  const double angle = radians(args.real("angle"));
  place_mesh(scene, add_mesh(scene, std::move(mesh)), "walls", glm::vec3(0.0f), angle);
  // Aerial three-quarter view of the whole plan (its bounds rotate with it).
  const float reach = 0.5f * (span + kThickness) * std::sqrt(2.0f);
  const Aabb plan{glm::vec3(-reach, 0.0f, -reach), glm::vec3(reach, kHeight, reach)};
  scene.cameras.push_back(frame_box("aerial", plan, glm::vec3(0.4f, 1.0f, 0.7f)));
  scene.lights.push_back(directional_light("sun", glm::vec3(-0.3f, -1.0f, -0.6f), 3.0f));
  finish(scene, args);
  return scene;
}

}  // namespace accelviz::procedural
