// accelviz calibrate [--scene SCENE] [--json]: this machine's cost of a
// ray-box test and of both ray-triangle tests, the SAH constants they imply
// (C_trav = 1), and with --scene what the calibrated constants change in the
// BVH (SAH cost under the calibrated constants, measured rays/s on primary rays).
#include <cstdio>
#include <iostream>
#include <optional>

#include "app/cli_common.h"
#include "core/analysis/calibrate.h"
#include "core/analysis/sweep.h"
#include "core/query/camera.h"
#include "core/query/ray_sets.h"
#include "core/util/huge_page_allocator.h"
#include "core/util/json_text.h"
#include "core/util/parallel.h"

namespace accelviz::cli {

namespace {

struct CalibrateCliOptions {
  std::string scene;
  bool json = false;
  int repeat = 5;
  std::string size = "640x480";
  unsigned threads = 0;
  std::string triangle_test = "watertight";
};

nlohmann::json figures_json(const CalibratedTree& f) {
  return {{"c_trav", f.c_trav},
          {"c_isect", f.c_isect},
          {"build_ms", f.build_ms},
          {"sah_cost_own_constants", f.sah_own},
          {"sah_cost_calibrated_constants", f.sah_calibrated},
          {"rays_per_s", f.rays_per_s},
          {"nodes_per_ray", f.nodes_per_ray},
          {"prims_per_ray", f.prims_per_ray}};
}

int run_calibrate(const CalibrateCliOptions& o, const GlobalOptions& global) {
  use_fixed_malloc_thresholds();  // the two trees' builds compare fairly
  const ImageSize size = parse_size(o.size);
  const QueryOptions q{parse_triangle_test(o.triangle_test), true};
  Progress progress(global.quiet);
  // The scene and its camera first: a name that does not load, or a scene
  // that cannot be framed, is said before seconds of micro-benchmarks.
  std::optional<Scene> scene;
  std::vector<Ray> rays;
  if (!o.scene.empty()) {
    progress.begin("loading " + o.scene);
    scene = load_scene_noting_warnings(o.scene, global.quiet);
    require_flattened(*scene, o.scene, "calibrate --scene");
    rays = primary_rays(camera_for("", *scene, size, /*has_camera_option=*/false), size.width, size.height);
    progress.end(count_of(scene->triangles.size(), "triangle"));
  }
  progress.begin("micro-benchmarks (box, watertight, fast)");
  CalibrateOptions copts;
  copts.repeat = o.repeat;
  const Calibration c = calibrate(copts);
  progress.end();
  nlohmann::json j = {{"ns_box_test", c.ns_box},
                      {"ns_triangle_watertight", c.ns_triangle_watertight},
                      {"ns_triangle_fast", c.ns_triangle_fast},
                      {"box_hit_fraction", c.box_hit_fraction},
                      {"triangle_hit_fraction", c.triangle_hit_fraction},
                      {"c_trav", 1.0},
                      {"c_isect_watertight", c.c_isect_watertight()},
                      {"c_isect_fast", c.c_isect_fast()},
                      {"repeat", o.repeat}};
  CalibrationReport report;
  if (scene) {
    progress.begin("BVH with the default and the calibrated constants");
    report = compare_calibrated_bvh(scene->triangles, rays, c, q, o.threads, o.repeat);
    progress.end();
    j["scene"] = {{"name", o.scene},
                  {"triangles", scene->triangles.size()},
                  {"rays", rays.size()},
                  {"threads", resolve_threads(o.threads)},
                  {"triangle_test", o.triangle_test},
                  {"default", figures_json(report.with_default)},
                  {"calibrated", figures_json(report.with_calibrated)}};
  }
  if (o.json) {
    j["machine"] = machine_json(resolve_threads(o.threads));
    write_stdout(json_text(j, 2) + '\n');
    return 0;
  }
  std::printf("ray-box slab test           %7.2f ns\n", c.ns_box);
  std::printf("ray-triangle, watertight    %7.2f ns  (C_isect/C_trav = %.3f)\n", c.ns_triangle_watertight,
              c.c_isect_watertight());
  std::printf("ray-triangle, fast (M-T)    %7.2f ns  (C_isect/C_trav = %.3f)\n", c.ns_triangle_fast, c.c_isect_fast());
  std::printf("C_trav = 1 is one inner-node visit = two box tests; medians of %s, one thread\n",
              count_of(static_cast<std::size_t>(o.repeat), "loop").c_str());
  if (!o.scene.empty()) {
    std::printf("\n%s, %s, %s test:\n", o.scene.c_str(),
                count_of(static_cast<std::size_t>(size.width) * size.height, "primary ray").c_str(),
                o.triangle_test.c_str());
    std::printf("  %-28s %10s %14s %10s %10s %10s\n", "constants", "build ms", "SAH (calib.)", "Mrays/s", "nodes/ray",
                "prims/ray");
    const CalibratedTree &def = report.with_default, &cal = report.with_calibrated;
    std::printf("  %-28s %10.1f %14.3f %10.2f %10.2f %10.2f\n", "default (1, 1)", def.build_ms, def.sah_calibrated,
                def.rays_per_s / 1e6, def.nodes_per_ray, def.prims_per_ray);
    char label[64];
    std::snprintf(label, sizeof label, "calibrated (1, %.3f)", report.c_isect);
    std::printf("  %-28s %10.1f %14.3f %10.2f %10.2f %10.2f\n", label, cal.build_ms, cal.sah_calibrated,
                cal.rays_per_s / 1e6, cal.nodes_per_ray, cal.prims_per_ray);
  }
  return 0;
}

Command add_calibrate_command(CLI::App& parent, const GlobalOptions& global) {
  auto o = std::make_shared<CalibrateCliOptions>();
  CLI::App* sub = parent.add_subcommand(
      "calibrate", "Measure this machine's ray-box and ray-triangle test costs and the SAH constants they imply; "
                   "with --scene, compare the BVH built with default and calibrated constants");
  sub->add_option("--scene", o->scene, "Scene to compare default and calibrated BVH constants on")
      ->check(CLI::Validator(
          [](std::string& v) { return v.empty() ? std::string("an empty scene name") : std::string(); }, "SCENE"));
  sub->add_flag("--json", o->json, "Print one JSON document instead of text");
  sub->add_option("--repeat,-n", o->repeat, "Timed loops per figure (median)")->check(CLI::Range(1, 100))->capture_default_str();
  sub->add_option("--size", o->size, "--scene: primary rays, one per pixel of a WxH image")
      ->check(size_validator())
      ->capture_default_str();
  add_threads_option(sub, o->threads, "--scene: build and trace threads (0: all)");
  add_triangle_test_option(sub, o->triangle_test, "--scene: which test's constant to build with and trace");
  return {sub, [o, &global] { return run_calibrate(*o, global); }};
}

const CommandRegistration register_calibrate{add_calibrate_command};

}  // namespace

}  // namespace accelviz::cli
