// Effects by scene (see effects.h).
#include "core/scene/effects.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "core/geometry/shapes.h"
#include "core/query/camera.h"
#include "core/util/one_line.h"

namespace accelviz {

namespace {

void apply_force(Effect& e, bool force) {
  if (!force || e.on) return;
  if (!e.forceable) {
    e.reason += " (asked for, but cannot be forced)";
    return;
  }
  e.on = true;
  e.forced = true;
  e.reason = "forced on by the user; the scene alone would not: " + e.reason;
}

}  // namespace

SceneEffects decide_effects(const Scene& scene, const EffectForces& forces) {
  SceneEffects fx;
  fx.shadow_rays.name = "shadow-rays";
  fx.shadow_rays.on = shadow_rays_wanted(scene, {});
  const std::size_t casting = casting_lights(scene).size(), dark = scene.lights.size() - casting;
  const std::string dark_note =
      dark == 0 ? "" : "; " + count_of(dark, "light") + " of intensity or colour 0 left out (they light nothing)";
  fx.shadow_rays.reason = casting == 0 ? (scene.lights.empty() ? "no lights: nothing casts a shadow"
                                                               : count_of(dark, "light") +
                                                                     " but none gives light (intensity or colour 0): "
                                                                     "nothing casts a shadow")
                                       : count_of(casting, "light") + ": one any-hit ray per light per hit" + dark_note;

  fx.per_frame_updates.name = "per-frame-updates";
  const std::size_t channels = rigid_channels_moving(scene);
  fx.per_frame_updates.on = scene_animates(scene);
  if (fx.per_frame_updates.on) {
    std::string what;
    if (channels > 0) what = count_of(channels, "animation channel") + " (rigid: instance transforms + TLAS)";
    const std::size_t deforming = deforming_meshes(scene).size();
    if (deforming > 0)
      what += (what.empty() ? "" : ", ") + count_of(deforming, "deforming mesh") + " (BLAS refit or rebuild)";
    fx.per_frame_updates.reason = what;
  } else {
    std::size_t all = 0;
    for (const Animation& a : scene.animations) all += a.channels.size();
    fx.per_frame_updates.reason =
        all == 0 ? "nothing animates: the structure is built once"
                 : count_of(all, "animation channel") +
                       " but none moves geometry (a camera, a light, an empty node or one outside the scene, or "
                       "values that never change): the structure is built once";
  }

  fx.two_level.name = "two-level";
  std::vector<std::size_t> refs(scene.meshes.size(), 0);
  for (const Instance& inst : scene.instances)
    if (inst.mesh < refs.size() && !scene.meshes[inst.mesh].indices.empty()) ++refs[inst.mesh];
  std::size_t shared = 0;
  for (std::size_t r : refs) shared += r > 1;
  fx.two_level.on = scene.has_instancing() || (scene.triangles.empty() && !scene.instances.empty());
  if (scene.triangles.empty() && !scene.instances.empty())
    fx.two_level.reason = "instanced and too large to flatten: only the two-level structure holds it";
  else if (fx.two_level.on)
    fx.two_level.reason = count_of(shared, "mesh") + " instanced more than once (" +
                          count_of(scene.instances.size(), "instance") + "): one BLAS per unique mesh";
  else
    fx.two_level.reason = "no mesh is instanced twice: a single flattened BVH";

  fx.textures.name = "textures";
  fx.textures.on = false;
  fx.textures.forceable = false;
  fx.textures.reason = "no view draws textures or materials: the loader skips image decoding";

  apply_force(fx.shadow_rays, forces.shadow_rays);
  if (fx.shadow_rays.forced && casting == 0)
    fx.shadow_rays.reason += "; they aim at a synthetic point light above the scene";
  apply_force(fx.per_frame_updates, forces.per_frame_updates);
  apply_force(fx.two_level, forces.two_level);
  apply_force(fx.textures, forces.textures);
  return fx;
}

bool set_force(EffectForces& f, const std::string& name) {
  if (name == "shadow-rays")
    f.shadow_rays = true;
  else if (name == "per-frame-updates")
    f.per_frame_updates = true;
  else if (name == "two-level")
    f.two_level = true;
  else if (name == "textures")
    f.textures = true;
  else
    return false;
  return true;
}

std::string effects_text(const SceneEffects& fx) {
  std::string out;
  for (const Effect& e : fx.list()) {
    char line[64];
    std::snprintf(line, sizeof line, "  %-18s %-3s %-7s ", e.name.c_str(), e.on ? "on" : "off",
                  e.forced ? "forced" : "");
    out += line + e.reason + "\n";
  }
  return out;
}

std::vector<Light> casting_lights(const Scene& scene) {
  std::vector<Light> out;
  for (const Light& l : scene.lights)
    if (l.intensity > 0.0f && std::max({l.color.x, l.color.y, l.color.z}) > 0.0f) out.push_back(l);
  return out;
}

bool shadow_rays_wanted(const Scene& scene, const EffectForces& forces) {
  return !casting_lights(scene).empty() || forces.shadow_rays;
}

std::vector<Light> shadow_lights(const Scene& scene, bool wanted) {
  if (!wanted) return {};
  std::vector<Light> lights = casting_lights(scene);
  if (!lights.empty()) return lights;
  return {synthetic_light(scene)};
}

Light synthetic_light(const Scene& scene) {
  return synthetic_light(
      scene.bounds(), scene.cameras.empty() ? std::nullopt : std::optional<glm::vec3>(scene.cameras.front().position));
}

Light synthetic_light(const Aabb& bounds, std::optional<glm::vec3> eye) {
  Light light;
  light.name = "synthetic";
  light.kind = Light::Kind::point;
  if (bounds.is_empty()) {
    light.position = glm::vec3(0.0f, 10.0f, 0.0f);
    return light;
  }
  float radius = 0.5f * glm::length(bounds.extent());
  if (!(radius > 0.0f)) radius = 1.0f;
  glm::vec3 side = glm::normalize(glm::vec3(1.0f, 0.0f, 1.4f));  // the framing view's side
  if (eye) {
    const glm::vec3 towards(eye->x - bounds.center().x, 0.0f, eye->z - bounds.center().z);
    const float len = glm::length(towards);
    if (len > 0.0f && std::isfinite(len)) side = towards / len;
  }
  light.position = bounds.center() + glm::vec3(0.0f, radius, 0.0f) + 0.5f * radius * side;
  return light;
}

Ray shadow_ray(const Ray& primary, const Hit& h, const Light& l) {
  const glm::vec3 p = primary.at(h.t);
  // Offset along the normal, toward the side the ray came from, on the scale
  // of the coordinates p was computed from (offset_ray_origin; a fixed floor
  // of 1e-4 put a tiny scene's origins beyond it).
  const glm::vec3 n = glm::dot(h.ng, primary.direction) < 0.0f ? h.ng : -h.ng;  // unit
  const auto largest = [](const glm::vec3& v) { return std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)}); };
  const glm::vec3 o = offset_ray_origin(p, n, std::max(largest(primary.origin), largest(p)));
  const bool directional = l.kind == Light::Kind::directional;
  const glm::vec3 d = directional ? -l.direction : l.position - o;
  return Ray(o, d, 0.0f, directional ? kInfinity : 1.0f);
}

FrameCounters run_frame(const Scene& scene, const SceneEffects& fx, const Accelerator& accel, const Camera& camera,
                        int width, int height, SceneAnimator* animator, float t) {
  FrameCounters c;
  if (fx.per_frame_updates.on && animator != nullptr) {
    const FrameStats fs = animator->step(t);
    c.refits = fs.refits;
    c.rebuilds = fs.rebuilds;
    c.tlas_rebuilds = fs.tlas_rebuilt ? 1 : 0;
    c.moved_instances = fs.moved_instances;
  }
  const QueryOptions qo;
  const std::vector<Light> lights = shadow_lights(scene, fx.shadow_rays.on);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const Ray ray = primary_ray(camera, x, y, width, height);
      ++c.primary_rays;
      const Hit h = accel.closest_hit(ray, qo);
      if (!h.valid() || !fx.shadow_rays.on) continue;
      for (const Light& l : lights) {
        ++c.shadow_rays;
        (void)accel.any_hit(shadow_ray(ray, h, l), qo);
      }
    }
  return c;
}

}  // namespace accelviz
