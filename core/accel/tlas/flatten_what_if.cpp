// The flatten what-if (see flatten_what_if.h).
#include "core/accel/tlas/flatten_what_if.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "core/query/camera.h"

namespace accelviz {

Scene flatten_instances(const Scene& scene, std::span<const std::uint32_t> selected) {
  std::vector<char> merged(scene.instances.size(), 0);
  for (std::uint32_t id : selected) {
    if (id >= scene.instances.size())
      throw std::invalid_argument("flatten: no instance " + std::to_string(id) + " (the scene has " +
                                  std::to_string(scene.instances.size()) + ")");
    if (merged[id]) throw std::invalid_argument("flatten: instance " + std::to_string(id) + " listed twice");
    merged[id] = 1;
  }
  Scene out = scene;
  out.instances.clear();
  Mesh big;
  big.name = "flattened";
  const auto finite3 = [](const glm::vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
  };
  for (std::size_t i = 0; i < scene.instances.size(); ++i) {
    const Instance& inst = scene.instances[i];
    if (!merged[i]) {
      out.instances.push_back(inst);
      continue;
    }
    const Mesh& m = scene.meshes[inst.mesh];
    for (const glm::uvec3& idx : m.indices) {
      glm::vec3 v[3];
      bool ok = true;
      for (int k = 0; k < 3; ++k) {
        v[k] = glm::vec3(inst.transform * glm::vec4(m.positions[idx[k]], 1.0f));
        ok = ok && finite3(v[k]);
      }
      if (!ok) continue;
      const auto base = static_cast<std::uint32_t>(big.positions.size());
      big.positions.insert(big.positions.end(), {v[0], v[1], v[2]});
      big.indices.push_back({base, base + 1, base + 2});
    }
  }
  if (!big.indices.empty()) {
    Node n;
    n.name = "flattened";
    n.mesh = static_cast<int>(out.meshes.size());
    out.nodes.push_back(n);
    out.roots.push_back(static_cast<int>(out.nodes.size()) - 1);
    Instance inst;
    inst.mesh = static_cast<std::uint32_t>(out.meshes.size());
    inst.node = static_cast<std::uint32_t>(out.nodes.size()) - 1;
    out.meshes.push_back(std::move(big));
    out.instances.push_back(inst);
  }
  if (!scene.triangles.empty())
    out.flatten();
  else
    out.triangles.clear();
  return out;
}

namespace {

TwoLevelFigures measure(const Scene& scene, const Camera& camera, int width, int height, const TlasOptions& opts) {
  const Tlas t(scene, opts);
  TwoLevelFigures f;
  const BuildStats& b = t.build_stats();
  f.sah_cost = b.sah_cost;
  f.memory_bytes = b.memory_bytes;
  f.build_ms = b.build_ms;
  f.instances = t.instances().size();
  f.blas = t.blas_count();
  double nodes = 0.0, prims = 0.0, inst = 0.0;
  const QueryOptions qo;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      TwoLevelRayStats s;
      const Hit h = t.closest_hit_two_level(primary_ray(camera, x, y, width, height), qo, &s);
      ++f.rays;
      if (h.valid()) ++f.hits;
      nodes += s.tlas_nodes + s.blas_nodes;
      prims += s.prim_tests;
      inst += s.instances_visited;
    }
  if (f.rays > 0) {
    f.mean_nodes = nodes / static_cast<double>(f.rays);
    f.mean_prims = prims / static_cast<double>(f.rays);
    f.mean_instances = inst / static_cast<double>(f.rays);
  }
  return f;
}

}  // namespace

FlattenWhatIf flatten_what_if(const Scene& scene, std::span<const std::uint32_t> selected, const Camera& camera,
                              int width, int height, const TlasOptions& opts) {
  FlattenWhatIf w;
  const Scene flat = flatten_instances(scene, selected);
  w.merged_instances = selected.size();
  if (!flat.instances.empty() && flat.instances.back().node + 1 == flat.nodes.size() &&
      flat.nodes.back().name == "flattened" && !selected.empty())
    w.merged_triangles = flat.meshes[flat.instances.back().mesh].indices.size();
  w.two_level = measure(scene, camera, width, height, opts);
  w.flattened = measure(flat, camera, width, height, opts);
  return w;
}

}  // namespace accelviz
