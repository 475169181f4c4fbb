#include "ui/app/ray_inspection.h"

#include "core/geometry/shapes.h"
#include "core/query/camera.h"

#include <cmath>
#include <unordered_set>

namespace accelviz {
namespace {

nlohmann::json number_or_null(float v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

nlohmann::json vec(const glm::vec3& v) {
  return nlohmann::json::array({v.x, v.y, v.z});
}

nlohmann::json stats_json(const RayStats& s) {
  return {{"nodes_visited", s.nodes_visited}, {"box_tests", s.box_tests},
          {"prim_tests", s.prim_tests},       {"nodes_culled", s.nodes_culled},
          {"nodes_missed", s.nodes_missed},   {"repeated_prim_tests", s.repeated_prim_tests},
          {"empty_cells", s.empty_cells}};
}

}  // namespace

RayInspection inspect_pixel(const BuiltStructure& built, const Camera& camera, int x, int y, int width, int height,
                            const QueryOptions& query) {
  RayInspection like;
  like.x = x;
  like.y = y;
  like.width = width;
  like.height = height;
  like.camera = camera;
  like.ray = primary_ray(camera, x, y, width, height);
  return inspect_ray(built, like, query);
}

RayInspection inspect_ray(const BuiltStructure& built, const RayInspection& like, const QueryOptions& query) {
  RayInspection r;
  r.x = like.x;
  r.y = like.y;
  r.width = like.width;
  r.height = like.height;
  r.camera = like.camera;
  r.ray = like.ray;
  r.structure = built.accel->name();
  r.hit = built.accel->closest_hit(r.ray, query, &r.stats, &r.trace);
  if (!r.hit.valid()) return r;

  // Shadow rays leave from the hit offset to the side the primary ray came
  // from (Wachter & Binder 2019), so they never re-hit their own surface.
  const glm::vec3 p = r.ray.at(r.hit.t);
  glm::vec3 n = r.hit.ng;
  if (glm::dot(n, r.ray.direction) > 0.0f) n = -n;
  const auto largest = [](const glm::vec3& v) { return std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)}); };
  const glm::vec3 origin = offset_ray_origin(p, n, std::max(largest(r.ray.origin), largest(p)));
  const auto& lights = built.scene->scene.lights;
  for (std::size_t i = 0; i < lights.size(); ++i) {
    const Light& l = lights[i];
    glm::vec3 dir;
    float tmax = kInfinity;
    if (l.kind == Light::Kind::directional) {
      dir = -l.direction;
    } else {
      const glm::vec3 to = l.position - origin;
      const float dist = glm::length(to);
      if (!(dist > 0.0f)) continue;
      dir = to / dist;
      tmax = dist * (1.0f - 1e-4f);  // stop short of the light itself
    }
    if (glm::dot(dir, n) <= 0.0f) continue;  // the light is behind the surface
    ShadowRay s;
    s.light = i;
    s.light_name = l.name;
    s.ray = Ray(origin, dir, 0.0f, tmax);
    s.occluded = built.accel->any_hit(s.ray, query, &s.stats);
    r.shadows.push_back(std::move(s));
  }
  return r;
}

const char* step_kind_name(VisitStep::Kind k) {
  switch (k) {
    case VisitStep::Kind::node_entered:
      return "entered";
    case VisitStep::Kind::node_missed:
      return "missed";
    case VisitStep::Kind::node_culled:
      return "culled";
    case VisitStep::Kind::prim_hit:
      return "prim-hit";
    case VisitStep::Kind::prim_miss:
      return "prim-miss";
  }
  return "?";
}

ReplayState replay_upto(const VisitTrace& trace, std::size_t upto) {
  ReplayState s;
  std::unordered_set<std::uint32_t> seen;
  for (std::size_t i = 0; i < trace.steps.size() && i <= upto; ++i) {
    const VisitStep& st = trace.steps[i];
    switch (st.kind) {
      case VisitStep::Kind::node_entered:
        s.entered.push_back(st.id);
        s.current_node = st.id;
        break;
      case VisitStep::Kind::node_missed:
      case VisitStep::Kind::node_culled:
        s.current_node = st.id;
        break;
      case VisitStep::Kind::prim_hit:
      case VisitStep::Kind::prim_miss:
        if (seen.insert(st.id).second) s.tested.push_back(st.id);
        break;
    }
  }
  return s;
}

std::vector<std::uint32_t> replay_box_ids(const VisitTrace& trace, std::size_t step) {
  const ReplayState r = replay_upto(trace, step);
  std::vector<std::uint32_t> ids = r.entered;
  const bool at_end = step + 1 >= trace.steps.size();
  if (!at_end && r.current_node && (r.entered.empty() || r.entered.back() != *r.current_node))
    ids.push_back(*r.current_node);
  return ids;
}

nlohmann::json inspection_json(const RayInspection& r, std::size_t replay_step) {
  nlohmann::json steps = nlohmann::json::array();
  std::size_t entered = 0, prim_tests = 0;
  for (const VisitStep& s : r.trace.steps) {
    steps.push_back({{"kind", step_kind_name(s.kind)},
                     {"id", s.id},
                     {"t_entry", number_or_null(s.t_entry)},
                     {"t_exit", number_or_null(s.t_exit)}});
    if (s.kind == VisitStep::Kind::node_entered) ++entered;
    if (s.kind == VisitStep::Kind::prim_hit || s.kind == VisitStep::Kind::prim_miss) ++prim_tests;
  }
  nlohmann::json hit = nullptr;
  if (r.hit.valid())
    hit = {{"prim", r.hit.prim},     {"t", r.hit.t}, {"u", r.hit.u}, {"v", r.hit.v}, {"point", vec(r.ray.at(r.hit.t))},
           {"normal", vec(r.hit.ng)}};
  nlohmann::json shadows = nlohmann::json::array();
  for (const ShadowRay& s : r.shadows)
    shadows.push_back({{"light", s.light},
                       {"name", s.light_name},
                       {"origin", vec(s.ray.origin)},
                       {"direction", vec(s.ray.direction)},
                       {"tmax", number_or_null(s.ray.tmax)},
                       {"occluded", s.occluded},
                       {"stats", stats_json(s.stats)}});
  return {{"pixel", {r.x, r.y}},
          {"size", {r.width, r.height}},
          {"structure", r.structure},
          {"ray", {{"origin", vec(r.ray.origin)}, {"direction", vec(r.ray.direction)}}},
          {"hit", hit},
          {"stats", stats_json(r.stats)},
          {"entered_nodes", entered},
          {"prim_tests", prim_tests},
          {"steps", steps},
          {"replay_step", replay_step},
          {"shadows", shadows}};
}

}  // namespace accelviz
