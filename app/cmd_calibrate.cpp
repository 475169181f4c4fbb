// accelviz calibrate [--scene SCENE] [--json]: this machine's cost of a
// ray-box test and of both ray-triangle tests, the SAH constants they imply
// (C_trav = 1), and with --scene what the calibrated constants change in the
// BVH (SAH cost under the calibrated constants, measured rays/s on primary rays).
#include "app/cli_common.h"

#include "core/analysis/calibrate.h"
#include "core/analysis/sah.h"
#include "core/query/batch.h"
#include "core/query/camera.h"
#include "core/query/ray_sets.h"
#include "core/util/huge_page_allocator.h"
#include "core/util/parallel.h"

#include <cstdio>
#include <iostream>

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

struct BvhFigures {
  double build_ms = 0, sah_own = 0, sah_calibrated = 0, rays_per_s = 0, nodes_per_ray = 0, prims_per_ray = 0;
};

BvhFigures measure_bvh(const Scene& scene, const std::vector<Ray>& rays, const BvhOptions& opts, double ctrav,
                       double cisect, const QueryOptions& q, unsigned threads, int repeat) {
  BvhFigures f;
  const Bvh bvh(scene.triangles, opts);
  f.build_ms = bvh.build_stats().build_ms;
  f.sah_own = bvh.build_stats().sah_cost;
  f.sah_calibrated = bvh_sah_cost(bvh.nodes(), ctrav, cisect);  // both trees judged by the same constants
  std::vector<Hit> hits(rays.size());
  std::vector<double> rps;
  for (int r = 0; r < repeat; ++r) {
    const auto t0 = Clock::now();
    trace_closest(bvh, rays, hits, q, threads);
    const double ms = ms_since(t0);
    rps.push_back(ms > 0 ? static_cast<double>(rays.size()) / (ms * 1e-3) : 0.0);
  }
  f.rays_per_s = median(rps);
  std::vector<RayStats> stats(rays.size());
  trace_closest(bvh, rays, hits, q, threads, stats);
  for (const RayStats& s : stats) {
    f.nodes_per_ray += s.nodes_visited;
    f.prims_per_ray += s.prim_tests;
  }
  if (!rays.empty()) {
    f.nodes_per_ray /= static_cast<double>(rays.size());
    f.prims_per_ray /= static_cast<double>(rays.size());
  }
  return f;
}

nlohmann::json figures_json(const BvhFigures& f, double ctrav, double cisect) {
  return {{"c_trav", ctrav},           {"c_isect", cisect},
          {"build_ms", f.build_ms},    {"sah_cost_own_constants", f.sah_own},
          {"sah_cost_calibrated_constants", f.sah_calibrated},
          {"rays_per_s", f.rays_per_s}, {"nodes_per_ray", f.nodes_per_ray},
          {"prims_per_ray", f.prims_per_ray}};
}

int run_calibrate(const CalibrateCliOptions& o, const GlobalOptions& global) {
  use_fixed_malloc_thresholds();  // the two trees' builds compare fairly
  const ImageSize size = parse_size(o.size);
  const QueryOptions q{parse_triangle_test(o.triangle_test), true};
  Progress progress(global.quiet);
  progress.begin("micro-benchmarks (box, watertight, fast)");
  CalibrateOptions copts;
  copts.repeat = o.repeat;
  const Calibration c = calibrate(copts);
  progress.end();
  const double cisect = q.triangle_test == TriangleTest::watertight ? c.c_isect_watertight() : c.c_isect_fast();

  nlohmann::json j = {{"ns_box_test", c.ns_box},
                      {"ns_triangle_watertight", c.ns_triangle_watertight},
                      {"ns_triangle_fast", c.ns_triangle_fast},
                      {"box_hit_fraction", c.box_hit_fraction},
                      {"triangle_hit_fraction", c.triangle_hit_fraction},
                      {"c_trav", 1.0},
                      {"c_isect_watertight", c.c_isect_watertight()},
                      {"c_isect_fast", c.c_isect_fast()},
                      {"repeat", o.repeat}};
  BvhFigures def, cal;
  BvhOptions dopts, copts_bvh;
  if (!o.scene.empty()) {
    progress.begin("loading " + o.scene);
    const Scene scene = load_scene_noting_warnings(o.scene, global.quiet);
    progress.end(std::to_string(scene.triangles.size()) + " triangles");
    const std::vector<Ray> rays = primary_rays(camera_for("", scene, size), size.width, size.height);
    const unsigned threads = resolve_threads(o.threads);
    dopts.threads = copts_bvh.threads = o.threads;
    dopts.compute_epo = copts_bvh.compute_epo = false;
    copts_bvh.cost_traversal = 1.0f;
    copts_bvh.cost_intersect = static_cast<float>(cisect);
    progress.begin("BVH with the default constants");
    def = measure_bvh(scene, rays, dopts, 1.0, cisect, q, threads, o.repeat);
    progress.end();
    progress.begin("BVH with the calibrated constants");
    cal = measure_bvh(scene, rays, copts_bvh, 1.0, cisect, q, threads, o.repeat);
    progress.end();
    j["scene"] = {{"name", o.scene},
                  {"triangles", scene.triangles.size()},
                  {"rays", rays.size()},
                  {"threads", threads},
                  {"triangle_test", o.triangle_test},
                  {"default", figures_json(def, dopts.cost_traversal, dopts.cost_intersect)},
                  {"calibrated", figures_json(cal, 1.0, cisect)}};
  }
  if (o.json) {
    std::cout << j.dump(2) << std::endl;
    return 0;
  }
  std::printf("ray-box slab test           %7.2f ns\n", c.ns_box);
  std::printf("ray-triangle, watertight    %7.2f ns  (C_isect/C_trav = %.3f)\n", c.ns_triangle_watertight,
              c.c_isect_watertight());
  std::printf("ray-triangle, fast (M-T)    %7.2f ns  (C_isect/C_trav = %.3f)\n", c.ns_triangle_fast, c.c_isect_fast());
  std::printf("C_trav = 1 is one inner-node visit = two box tests; medians of %d loops, one thread\n", o.repeat);
  if (!o.scene.empty()) {
    std::printf("\n%s, %zu primary rays, %s test:\n", o.scene.c_str(),
                static_cast<std::size_t>(size.width) * size.height, o.triangle_test.c_str());
    std::printf("  %-28s %10s %14s %10s %10s %10s\n", "constants", "build ms", "SAH (calib.)", "Mrays/s", "nodes/ray",
                "prims/ray");
    std::printf("  %-28s %10.1f %14.3f %10.2f %10.2f %10.2f\n", "default (1, 1)", def.build_ms, def.sah_calibrated,
                def.rays_per_s / 1e6, def.nodes_per_ray, def.prims_per_ray);
    char label[64];
    std::snprintf(label, sizeof label, "calibrated (1, %.3f)", cisect);
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
  sub->add_option("--scene", o->scene, "Scene to compare default and calibrated BVH constants on");
  sub->add_flag("--json", o->json, "Print one JSON document instead of text");
  sub->add_option("--repeat,-n", o->repeat, "Timed loops per figure (median)")->check(CLI::Range(1, 100))->capture_default_str();
  sub->add_option("--size", o->size, "--scene: primary rays, one per pixel of a WxH image")
      ->check(size_validator())
      ->capture_default_str();
  sub->add_option("--threads,-j", o->threads, "--scene: build and trace threads (0: all)")->capture_default_str();
  add_triangle_test_option(sub, o->triangle_test, "--scene: which test's constant to build with and trace");
  return {sub, [o, &global] { return run_calibrate(*o, global); }};
}

const CommandRegistration register_calibrate{add_calibrate_command};

}  // namespace

}  // namespace accelviz::cli
