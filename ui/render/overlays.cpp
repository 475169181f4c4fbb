#include "ui/render/overlays.h"

#include <algorithm>
#include <cmath>
#include <unordered_set>

namespace accelviz {

TranslucentQuad split_plane_quad(const Aabb& box, int axis, float position, const glm::vec4& fill,
                                 const glm::vec4& outline) {
  const int u = (axis + 1) % 3, v = (axis + 2) % 3;
  TranslucentQuad q;
  q.fill = fill;
  q.outline = outline;
  const float us[4] = {box.lo[u], box.hi[u], box.hi[u], box.lo[u]};
  const float vs[4] = {box.lo[v], box.lo[v], box.hi[v], box.hi[v]};
  for (int i = 0; i < 4; ++i) {
    q.corners[i][axis] = position;
    q.corners[i][u] = us[i];
    q.corners[i][v] = vs[i];
  }
  return q;
}

RayPath make_ray_path(const Ray& ray, const Hit& hit, const Aabb& scene_bounds) {
  RayPath path;
  const float diagonal = scene_bounds.is_empty() ? 1.0f : std::max(glm::length(scene_bounds.extent()), 1e-6f);
  float t_end = 0.0f;
  if (hit.valid()) {
    t_end = hit.t;
    path.hit = true;
    path.hit_point = ray.at(hit.t);
    const float len = glm::length(hit.ng);
    glm::vec3 n = len > 0.0f ? hit.ng / len : glm::vec3(0.0f);
    // Show the side the ray sees.
    if (glm::dot(n, ray.direction) > 0.0f) n = -n;
    path.hit_normal = n;
  } else {
    SlabInterval span{};
    if (!scene_bounds.is_empty() && intersect_slab(scene_bounds, ray.origin, ray.inv_dir, ray.tmin, ray.tmax, span)) {
      t_end = span.t_exit;
    } else {
      // Missed everything: draw it long enough to be seen passing the scene.
      const glm::vec3 centre = scene_bounds.is_empty() ? ray.origin : scene_bounds.center();
      t_end = glm::length(centre - ray.origin) + diagonal;
    }
    if (std::isfinite(ray.tmax)) t_end = std::min(t_end, ray.tmax);
  }
  path.normal_length = 0.1f * diagonal;
  path.polyline = {ray.at(ray.tmin), ray.at(t_end)};
  return path;
}

std::vector<Aabb> entered_boxes(const VisitTrace& trace, std::span<const BvhNode> nodes) {
  std::vector<Aabb> out;
  for (const VisitStep& s : trace.steps) {
    if (s.kind == VisitStep::Kind::node_entered && s.id < nodes.size()) out.push_back(nodes[s.id].bounds);
  }
  return out;
}

std::vector<std::uint32_t> tested_primitives(const VisitTrace& trace) {
  std::vector<std::uint32_t> out;
  std::unordered_set<std::uint32_t> seen;
  for (const VisitStep& s : trace.steps) {
    const bool prim = s.kind == VisitStep::Kind::prim_hit || s.kind == VisitStep::Kind::prim_miss;
    if (prim && seen.insert(s.id).second) out.push_back(s.id);
  }
  return out;
}

}  // namespace accelviz
