// accelviz rays SCENE --kind primary|diffuse|shadow --out FILE.rays: writes
// one of the benchmark's ray sets as a ray file, for `trace`, for other
// renderers, and for tests.
#include <cstdio>
#include <memory>

#include "app/cli_common.h"
#include "core/query/batch.h"
#include "core/query/camera.h"
#include "core/query/ray_file.h"
#include "core/query/ray_sets.h"
#include "core/scene/effects.h"

namespace accelviz::cli {

namespace {

struct RaysOptions {
  std::string scene;
  std::string kind = "primary";
  std::string out;
  std::string size = "800x600";
  std::string camera;
  std::uint64_t seed = 1;
  std::string structure = "bvh";
  unsigned threads = 0;
  bool force = false;
};

int run_rays(const RaysOptions& o, const GlobalOptions& global) {
  check_output_path(o.out, o.force);
  const ImageSize size = parse_size(o.size);
  const RayKind kind = parse_ray_kind(o.kind).value();
  Progress progress(global.quiet);

  progress.begin("loading " + o.scene);
  const Scene scene = load_scene_noting_warnings(o.scene, global.quiet);
  progress.end(count_of(scene.triangles.size(), "triangle"));

  const Camera camera =
      camera_for(o.camera, scene, size);
  std::vector<Ray> rays = primary_rays(camera, size.width, size.height);
  nlohmann::json j = {{"scene", o.scene}, {"kind", o.kind}, {"width", size.width}, {"height", size.height}};

  if (kind != RayKind::primary) {
    // Secondary rays start where the primary rays hit: trace those first.
    progress.begin("building " + o.structure + " for the primary hits");
    StructureOptions so;
    so.threads = o.threads;
    so.bvh.compute_epo = false;
    so.scene = &scene;  // "tlas" builds its two levels from the scene's meshes and instances
    const std::unique_ptr<Accelerator> accel = build_accelerator(o.structure, scene.triangles, so);
    std::vector<Hit> hits(rays.size());
    trace_closest(*accel, rays, hits, QueryOptions{}, o.threads);
    progress.end();
    if (kind == RayKind::diffuse) {
      rays = diffuse_rays(scene.triangles, rays, hits, o.seed);
      j["seed"] = o.seed;
    } else {
      const std::vector<Light> lights = shadow_lights(scene, true);
      if (casting_lights(scene).empty()) {  // no light, or none that gives light
        const glm::vec3 p = lights[0].position;
        if (!global.quiet)
          std::fprintf(
              stderr, "accelviz: %s has no lights%s: shadow rays aim at a synthetic point light at (%g, %g, %g)\n",
              o.scene.c_str(), scene.lights.empty() ? "" : " that give light (intensity or colour 0)", p.x, p.y, p.z);
        j["synthetic_light"] = {p.x, p.y, p.z};
      }
      rays = shadow_rays(scene.triangles, rays, hits, lights);
    }
  }
  write_rays(o.out, rays, o.force);
  j["rays"] = rays.size();
  j["out"] = absolute_path(o.out);
  print_json_line(j);
  return 0;
}

}  // namespace

Command add_rays_command(CLI::App& parent, const GlobalOptions& global) {
  auto o = std::make_shared<RaysOptions>();
  CLI::App* sub = parent.add_subcommand(
      "rays", "Generate a ray file (RAYS): primary camera rays, diffuse bounces from the primary hits, or shadow "
              "rays from the primary hits to the lights");
  sub->add_option("SCENE", o->scene, "Scene file (.gltf, .glb, .obj) or builtin:NAME[?key=value&...]")->required();
  sub->add_option("--kind,-k", o->kind, "Ray set: primary, diffuse, shadow")
      ->check(CLI::IsMember({"primary", "diffuse", "shadow"}))
      ->capture_default_str();
  sub->add_option("--out,-o", o->out, "Output ray file (never overwritten without --force)")->required();
  sub->add_option("--size", o->size, "Camera image size WxH: one primary ray per pixel")
      ->check(size_validator())
      ->capture_default_str();
  sub->add_option("--camera", o->camera,
                  "View: ex,ey,ez,tx,ty,tz[,fovdeg] or gltf:N; default: the scene's first camera, else a framing view");
  sub->add_option("--seed", o->seed, "Seed of the diffuse directions")->capture_default_str();
  sub->add_option("--structure,-s", o->structure, "Structure that finds the primary hits (diffuse, shadow)")
      ->check(CLI::IsMember(structure_names()))
      ->capture_default_str();
  add_threads_option(sub, o->threads, "Threads (0: all hardware threads)");
  sub->add_flag("--force,-f", o->force, "Overwrite an existing output file");
  return {sub, [o, &global] { return run_rays(*o, global); }};
}

}  // namespace accelviz::cli
