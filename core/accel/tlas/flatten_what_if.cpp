// The flatten what-if (see flatten_what_if.h).
#include "core/accel/tlas/flatten_what_if.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

#include "core/query/camera.h"
#include "core/util/timing.h"

namespace accelviz {

FlattenedScene flatten_instances(const Scene& scene, std::span<const std::uint32_t> selected) {
  std::vector<char> merged(scene.instances.size(), 0);
  for (std::uint32_t id : selected) {
    if (id >= scene.instances.size())
      throw std::invalid_argument("flatten: no instance " + std::to_string(id) + " (the scene has " +
                                  std::to_string(scene.instances.size()) + ")");
    if (merged[id]) throw std::invalid_argument("flatten: instance " + std::to_string(id) + " listed twice");
    merged[id] = 1;
  }
  // One mesh of merged world triangles, three 32-bit-indexed vertices each: refused beyond the
  // glTF loader's limit on world triangles (2^28, about 9.6 GB of them) rather than run out of
  // memory or wrap the indices.
  std::uint64_t to_merge = 0;
  for (std::size_t i = 0; i < scene.instances.size(); ++i)
    if (merged[i] && scene.instances[i].mesh < scene.meshes.size())
      to_merge += scene.meshes[scene.instances[i].mesh].indices.size();
  if (constexpr std::uint64_t kMaxMerged = std::uint64_t{1} << 28; to_merge > kMaxMerged)
    throw std::invalid_argument("flatten: the selected instances hold " + std::to_string(to_merge) +
                                " triangles, more than the " + std::to_string(kMaxMerged) +
                                " (2^28) one flattened mesh may hold");
  FlattenedScene result;
  result.scene = scene;
  Scene& out = result.scene;
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
  result.merged_triangles = big.indices.size();
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
  return result;
}

namespace {

using Clock = std::chrono::steady_clock;

/// PROGRESS mapped onto [lo, lo + span]; empty when PROGRESS is.
ProgressCallback sub_progress(const ProgressCallback& progress, double lo, double span) {
  if (!progress) return {};
  return [progress, lo, span](double f) { return progress(lo + span * f); };
}

/// Builds and traces one side; the build takes the first BUILD_SHARE of [0, 1] of PROGRESS.
TwoLevelFigures measure(const Scene& scene, const Camera& camera, int width, int height, const TlasOptions& opts,
                        const ProgressCallback& progress) {
  constexpr double kBuildShare = 0.4;
  const Tlas t(scene, opts, sub_progress(progress, 0.0, kBuildShare));
  TwoLevelFigures f;
  const BuildStats& b = t.build_stats();
  f.sah_cost = b.sah_cost;
  f.memory_bytes = b.memory_bytes;
  f.build_ms = b.build_ms;
  f.instances = t.instances().size();
  f.blas = t.blas_count();
  double nodes = 0.0, prims = 0.0, inst = 0.0;
  const QueryOptions qo;
  const auto t0 = Clock::now();
  for (int y = 0; y < height; ++y) {
    if (progress && !progress(kBuildShare + (1.0 - kBuildShare) * y / std::max(1, height))) throw BuildCancelled();
    for (int x = 0; x < width; ++x) {
      TwoLevelRayStats s;
      const Hit h = t.closest_hit_two_level(primary_ray(camera, x, y, width, height), qo, &s);
      ++f.rays;
      if (h.valid()) ++f.hits;
      nodes += s.tlas_nodes + s.blas_nodes;
      prims += s.prim_tests;
      inst += s.instances_visited;
    }
  }
  f.trace_ms = ms_since(t0);
  if (f.rays > 0) {
    f.mean_nodes = nodes / static_cast<double>(f.rays);
    f.mean_prims = prims / static_cast<double>(f.rays);
    f.mean_instances = inst / static_cast<double>(f.rays);
  }
  return f;
}

}  // namespace

FlattenWhatIf flatten_what_if(const Scene& scene, std::span<const std::uint32_t> selected, const Camera& camera,
                              int width, int height, const TlasOptions& opts, const ProgressCallback& progress) {
  FlattenWhatIf w;
  const FlattenedScene flat = flatten_instances(scene, selected);
  w.merged_instances = selected.size();
  w.merged_triangles = flat.merged_triangles;
  w.two_level = measure(scene, camera, width, height, opts, sub_progress(progress, 0.0, 0.5));
  w.flattened = measure(flat.scene, camera, width, height, opts, sub_progress(progress, 0.5, 0.5));
  if (progress) progress(1.0);
  return w;
}

}  // namespace accelviz
