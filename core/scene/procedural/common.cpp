#include "core/scene/procedural/reproducible_fp.h"  // first: see there

#include "core/scene/procedural/common.h"

#include "core/scene/procedural/random.h"

#include <utility>

namespace accelviz::procedural {

std::uint32_t add_mesh(Scene& scene, Mesh mesh) {
  scene.meshes.push_back(std::move(mesh));
  return static_cast<std::uint32_t>(scene.meshes.size() - 1);
}

void place_mesh(Scene& scene, std::uint32_t mesh, std::string node_name, const glm::vec3& translation, double yaw,
                float scale) {
  Node node;
  node.name = std::move(node_name);
  node.mesh = static_cast<int>(mesh);
  node.translation = translation;
  node.scale = glm::vec3(scale);
  const SinCos full = sin_cos(yaw);
  const SinCos half = sin_cos(0.5 * yaw);
  // Rotation about +y by yaw: quaternion (w, x, y, z) = (cos yaw/2, 0, sin yaw/2, 0).
  node.rotation = glm::quat(static_cast<float>(half.cos), 0.0f, static_cast<float>(half.sin), 0.0f);
  const float c = static_cast<float>(full.cos);
  const float s = static_cast<float>(full.sin);
  // local = T * R * S, written out (glm is column-major: local[col][row]).
  glm::mat4 local(1.0f);
  local[0] = glm::vec4(scale * c, 0.0f, -scale * s, 0.0f);
  local[1] = glm::vec4(0.0f, scale, 0.0f, 0.0f);
  local[2] = glm::vec4(scale * s, 0.0f, scale * c, 0.0f);
  local[3] = glm::vec4(translation, 1.0f);
  node.local = local;
  scene.nodes.push_back(std::move(node));

  Instance inst;
  inst.mesh = mesh;
  inst.node = static_cast<std::uint32_t>(scene.nodes.size() - 1);
  inst.transform = local;  // root node: local is world
  scene.instances.push_back(inst);
}

Camera look_at(std::string name, const glm::vec3& eye, const glm::vec3& target, float yfov) {
  Camera cam;
  cam.name = std::move(name);
  cam.position = eye;
  cam.forward = glm::normalize(target - eye);
  // Gram-Schmidt of the +y hint against forward; fall back to +z when looking
  // straight up or down.
  glm::vec3 up = glm::vec3(0.0f, 1.0f, 0.0f) - cam.forward.y * cam.forward;
  if (glm::dot(up, up) < 1e-8f) up = glm::vec3(0.0f, 0.0f, 1.0f) - cam.forward.z * cam.forward;
  cam.up = glm::normalize(up);
  cam.yfov = yfov;
  return cam;
}

Camera frame_box(std::string name, const Aabb& box, const glm::vec3& from, float yfov) {
  const glm::vec3 centre = box.center();
  const float radius = 0.5f * glm::length(box.extent());
  const float half_fov_sin = static_cast<float>(sin_cos(0.5 * yfov).sin);
  const float distance = 1.1f * radius / half_fov_sin;
  return look_at(std::move(name), centre + distance * glm::normalize(from), centre, yfov);
}

Light point_light(std::string name, const glm::vec3& position, float intensity) {
  Light light;
  light.name = std::move(name);
  light.kind = Light::Kind::point;
  light.position = position;
  light.intensity = intensity;
  return light;
}

Light directional_light(std::string name, const glm::vec3& direction, float intensity) {
  Light light;
  light.name = std::move(name);
  light.kind = Light::Kind::directional;
  light.direction = glm::normalize(direction);
  light.intensity = intensity;
  return light;
}

Aabb mesh_bounds(const Mesh& mesh) {
  Aabb b;
  for (const glm::vec3& p : mesh.positions) b.extend(p);
  return b;
}

void append_box(Mesh& mesh, const glm::vec3& lo, const glm::vec3& hi) {
  const auto base = static_cast<std::uint32_t>(mesh.positions.size());
  // Corner k has x from bit 0, y from bit 1, z from bit 2.
  for (std::uint32_t k = 0; k < 8; ++k)
    mesh.positions.emplace_back((k & 1) ? hi.x : lo.x, (k & 2) ? hi.y : lo.y, (k & 4) ? hi.z : lo.z);
  // Two counter-clockwise (seen from outside) triangles per face.
  static constexpr std::uint32_t kFaces[6][4] = {
      {0, 4, 6, 2},  // -x
      {1, 3, 7, 5},  // +x
      {0, 1, 5, 4},  // -y
      {2, 6, 7, 3},  // +y
      {0, 2, 3, 1},  // -z
      {4, 5, 7, 6},  // +z
  };
  for (const auto& f : kFaces) {
    mesh.indices.emplace_back(base + f[0], base + f[1], base + f[2]);
    mesh.indices.emplace_back(base + f[0], base + f[2], base + f[3]);
  }
}

void append_ground(Mesh& mesh, const glm::vec2& lo, const glm::vec2& hi, float y) {
  const auto base = static_cast<std::uint32_t>(mesh.positions.size());
  mesh.positions.emplace_back(lo.x, y, lo.y);
  mesh.positions.emplace_back(lo.x, y, hi.y);
  mesh.positions.emplace_back(hi.x, y, hi.y);
  mesh.positions.emplace_back(hi.x, y, lo.y);
  // (lo,lo) -> (lo,hi) -> (hi,hi): (0,0,dz) x (dx,0,dz) = (0, dx dz, 0), facing +y.
  mesh.indices.emplace_back(base + 0, base + 1, base + 2);
  mesh.indices.emplace_back(base + 0, base + 2, base + 3);
}

void finish(Scene& scene, const BuiltinArgs& args) {
  scene.source = args.source;
  scene.roots.clear();
  for (std::size_t i = 0; i < scene.nodes.size(); ++i) scene.roots.push_back(static_cast<int>(i));
  scene.flatten();
}

}  // namespace accelviz::procedural
