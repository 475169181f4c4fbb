// accelviz info SCENE [--json]: what the loader found, dropped and noticed.
#include <charconv>
#include <cstdio>
#include <memory>

#include "app/cli_common.h"
#include "core/scene/effects.h"

namespace accelviz::cli {

namespace {

struct InfoOptions {
  std::string scene;
  bool json = false;
  std::vector<std::string> force;  ///< --force-effect NAME (repeatable)
};

nlohmann::json vec_json(const glm::vec3& v) {
  return {v.x, v.y, v.z};
}

/// The shortest decimal that reads back as `x` (std::to_chars): distinct floats print distinct.
std::string shortest_float(float x) {
  char buf[32];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, x);
  return ec == std::errc() ? std::string(buf, end) : std::to_string(x);
}

int run_info(const InfoOptions& o, const GlobalOptions& global) {
  const Scene scene = load_scene_noting_warnings(o.scene, /*quiet=*/true);
  (void)global;
  const Aabb b = scene.bounds();
  const bool empty = b.is_empty();
  EffectForces forces;
  for (const std::string& name : o.force)
    if (!set_force(forces, name))
      throw UsageError("--force-effect: unknown effect '" + name +
                       "' (valid: shadow-rays, per-frame-updates, two-level, textures)");
  const SceneEffects effects = decide_effects(scene, forces);
  if (o.json) {
    nlohmann::json j;
    j["scene"] = o.scene;
    j["triangles"] = scene.triangles.size();
    j["flattened"] = scene.flattened();
    j["instanced_triangles"] = scene.instanced_triangle_count();
    j["unique_triangles"] = scene.unique_triangle_count();
    j["meshes"] = scene.meshes.size();
    j["instances"] = scene.instances.size();
    j["nodes"] = scene.nodes.size();
    j["lights"] = scene.lights.size();
    j["cameras"] = scene.cameras.size();
    j["animations"] = scene.animations.size();
    j["has_instancing"] = scene.has_instancing();
    j["bounds"] = empty ? nlohmann::json(nullptr) : nlohmann::json{{"min", vec_json(b.lo)}, {"max", vec_json(b.hi)}};
    j["dropped_nonfinite"] = scene.report.dropped_nonfinite;
    j["degenerate"] = scene.report.degenerate;
    j["skipped_primitives"] = scene.report.skipped_primitives;
    j["warnings"] = scene.report.warnings;
    j["effects"] = nlohmann::json::array();
    for (const Effect& e : effects.list())
      j["effects"].push_back({{"name", e.name}, {"on", e.on}, {"forced", e.forced}, {"reason", e.reason}});
    j["structure"] = effects.structure();
    print_json_line(j);
    return 0;
  }
  std::printf("scene          %s\n", o.scene.c_str());
  std::printf("triangles      %s\n", triangle_count_text(scene).c_str());
  std::printf("meshes         %zu\n", scene.meshes.size());
  std::printf("instances      %zu (instancing: %s)\n", scene.instances.size(), scene.has_instancing() ? "yes" : "no");
  std::printf("nodes          %zu\n", scene.nodes.size());
  std::printf("lights         %zu\n", scene.lights.size());
  std::printf("cameras        %zu\n", scene.cameras.size());
  std::printf("animations     %zu\n", scene.animations.size());
  if (empty) {
    std::printf("bounds         (empty)\n");
  } else {
    // Each float in its shortest form that reads back as the same float (%g's
    // six digits printed a 2-wide box at 1e7 as (1e+07, ...) .. (1e+07, ...)).
    const auto v = [](const glm::vec3& p) {
      return "(" + shortest_float(p.x) + ", " + shortest_float(p.y) + ", " + shortest_float(p.z) + ")";
    };
    std::printf("bounds         %s .. %s, extent %s\n", v(b.lo).c_str(), v(b.hi).c_str(), v(b.extent()).c_str());
  }
  std::printf("dropped        %llu non-finite triangle(s)\n",
              static_cast<unsigned long long>(scene.report.dropped_nonfinite));
  std::printf("degenerate     %llu zero-area triangle(s), kept\n",
              static_cast<unsigned long long>(scene.report.degenerate));
  std::printf("skipped        %llu point/line primitive(s)\n",
              static_cast<unsigned long long>(scene.report.skipped_primitives));
  std::printf("warnings       %zu\n", scene.report.warnings.size());
  for (const std::string& w : scene.report.warnings) std::printf("  - %s\n", w.c_str());
  std::printf("effects        (structure: %s)\n%s", effects.structure().c_str(), effects_text(effects).c_str());
  return 0;
}

}  // namespace

Command add_info_command(CLI::App& parent, const GlobalOptions& global) {
  auto o = std::make_shared<InfoOptions>();
  CLI::App* sub = parent.add_subcommand("info",
                                        "Print what a scene contains: counts, bounds, dropped and "
                                        "degenerate triangles, loader warnings, the effects it calls for");
  sub->add_option("SCENE", o->scene, "Scene file (.gltf, .glb, .obj) or builtin:NAME[?key=value&...]")->required();
  sub->add_flag("--json", o->json, "Print one JSON object instead of text");
  sub->add_option("--force-effect", o->force,
                  "Force an effect on (repeatable): shadow-rays, per-frame-updates, two-level, textures");
  return {sub, [o, &global] { return run_info(*o, global); }};
}

}  // namespace accelviz::cli
