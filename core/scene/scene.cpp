#include "core/scene/scene.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/util/one_line.h"

namespace accelviz {

std::string no_triangles_message(const LoadReport& report) {
  std::string why;
  const auto add = [&why](const std::string& part) { why += (why.empty() ? " (" : "; ") + part; };
  if (report.dropped_nonfinite > 0)
    add(count_of(report.dropped_nonfinite, "triangle") +
        " dropped: " + (report.dropped_nonfinite == 1 ? "a NaN or infinite vertex" : "NaN or infinite vertices"));
  if (report.skipped_primitives > 0) add(count_of(report.skipped_primitives, "point/line primitive") + " skipped");
  return "scene contains no triangles" + (why.empty() ? std::string() : why + ")");
}

std::vector<glm::vec3> morphed_positions(const Mesh& mesh, const std::vector<float>& weights) {
  if (mesh.morph_deltas.empty()) return mesh.positions;
  std::vector<glm::vec3> out = mesh.morph_base.empty() ? mesh.positions : mesh.morph_base;
  const std::size_t targets = std::min(weights.size(), mesh.morph_deltas.size());
  for (std::size_t t = 0; t < targets; ++t) {
    const float w = weights[t];
    if (w == 0.0f) continue;
    const std::vector<glm::vec3>& d = mesh.morph_deltas[t];
    const std::size_t n = std::min(d.size(), out.size());
    for (std::size_t i = 0; i < n; ++i) out[i] += w * d[i];
  }
  return out;
}

Aabb Scene::bounds() const {
  Aabb b;
  for (const Triangle& t : triangles) b.extend(t.bounds());
  if (!triangles.empty() || instances.empty()) return b;
  // Not flattened (an instanced scene too large for it): the instances'
  // transformed mesh boxes.
  std::vector<Aabb> mesh_box(meshes.size());
  for (std::size_t m = 0; m < meshes.size(); ++m)
    for (const glm::vec3& p : meshes[m].positions) mesh_box[m].extend(p);
  for (const Instance& inst : instances) {
    if (inst.mesh >= meshes.size() || mesh_box[inst.mesh].is_empty()) continue;
    const Aabb& mb = mesh_box[inst.mesh];
    for (int i = 0; i < 8; ++i) {
      const glm::vec3 c((i & 1) ? mb.hi.x : mb.lo.x, (i & 2) ? mb.hi.y : mb.lo.y, (i & 4) ? mb.hi.z : mb.lo.z);
      b.extend(glm::vec3(inst.transform * glm::vec4(c, 1.0f)));
    }
  }
  return b;
}

static bool finite3(const glm::vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

/// Whether flatten() keeps one of MESH's triangles: one without a NaN or infinite vertex.
static bool has_finite_triangle(const Mesh& mesh) {
  for (const glm::uvec3& t : mesh.indices)
    if (finite3(mesh.positions[t.x]) && finite3(mesh.positions[t.y]) && finite3(mesh.positions[t.z])) return true;
  return false;
}

bool Scene::has_instancing() const {
  // A mesh without triangles (points, lines) instances nothing, nor one whose triangles the
  // flattening drops. refs: -1 for such a mesh, else the instances seen so far.
  std::vector<int> refs(meshes.size(), 0);
  for (const Instance& inst : instances) {
    if (inst.mesh >= refs.size() || refs[inst.mesh] < 0) continue;
    if (refs[inst.mesh] == 0 && !has_finite_triangle(meshes[inst.mesh])) {
      refs[inst.mesh] = -1;
      continue;
    }
    if (++refs[inst.mesh] > 1) return true;
  }
  return false;
}

std::uint64_t Scene::instanced_triangle_count() const {
  std::uint64_t total = 0;
  for (const Instance& inst : instances)
    if (inst.mesh < meshes.size()) total += meshes[inst.mesh].indices.size();
  return total;
}

/// Calls f(mesh) once for every mesh some instance references, in the order of first reference.
template <class F>
static void for_each_referenced_mesh(const Scene& scene, const F& f) {
  std::vector<bool> used(scene.meshes.size(), false);
  for (const Instance& inst : scene.instances)
    if (!used[inst.mesh]) {
      used[inst.mesh] = true;
      f(scene.meshes[inst.mesh]);
    }
}

std::uint64_t Scene::unique_triangle_count() const {
  std::uint64_t total = 0;
  for_each_referenced_mesh(*this, [&](const Mesh& m) { total += m.indices.size(); });
  return total;
}

std::size_t Scene::referenced_mesh_count() const {
  std::size_t count = 0;
  for_each_referenced_mesh(*this, [&](const Mesh&) { ++count; });
  return count;
}

std::string triangle_count_text(const Scene& scene) {
  const auto unique = [&] {
    const std::size_t meshes = scene.referenced_mesh_count();
    return std::to_string(scene.unique_triangle_count()) + " unique in " + std::to_string(meshes) +
           (meshes == 1 ? " mesh" : " meshes");
  };
  if (!scene.flattened())
    return std::to_string(scene.instanced_triangle_count()) + " instanced, not flattened (" + unique() + ")";
  if (scene.has_instancing()) return std::to_string(scene.triangles.size()) + " (from " + unique() + ")";
  return std::to_string(scene.triangles.size());
}

void Scene::flatten() {
  triangles.clear();
  report.dropped_nonfinite = 0;
  report.degenerate = 0;
  triangles.reserve(static_cast<std::size_t>(instanced_triangle_count()));
  for (Instance& inst : instances) {
    const Mesh& mesh = meshes[inst.mesh];
    inst.first_triangle = static_cast<std::uint32_t>(triangles.size());
    const bool identity = inst.transform == glm::mat4(1.0f);
    for (const glm::uvec3& idx : mesh.indices) {
      Triangle t;
      glm::vec3* v[3] = {&t.v0, &t.v1, &t.v2};
      for (int k = 0; k < 3; ++k) {
        const glm::vec3& p = mesh.positions[idx[k]];
        *v[k] = identity ? p : glm::vec3(inst.transform * glm::vec4(p, 1.0f));
      }
      if (!finite3(t.v0) || !finite3(t.v1) || !finite3(t.v2)) {
        ++report.dropped_nonfinite;
        continue;
      }
      // Zero area in double precision: kept (rays miss it), but counted.
      const glm::dvec3 a(t.v0), b(t.v1), c(t.v2);
      const glm::dvec3 n = glm::cross(b - a, c - a);
      if (n.x == 0.0 && n.y == 0.0 && n.z == 0.0) ++report.degenerate;
      triangles.push_back(t);
    }
    inst.triangle_count = static_cast<std::uint32_t>(triangles.size()) - inst.first_triangle;
  }
}

}  // namespace accelviz
