// accelviz refit SCENE --frames F --amplitude A [--rebuild-ratio R] --out DIR:
// refit decay of the BVH under a deterministic synthetic motion, frame by
// frame against a fresh build (core/analysis/refit_decay.h), written as
// refit.csv, refit.json and charts.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <glm/geometric.hpp>
#include <sstream>

#include "app/cli_common.h"
#include "core/analysis/chart.h"
#include "core/analysis/refit_decay.h"
#include "core/query/camera.h"
#include "core/query/ray_sets.h"
#include "core/util/json_text.h"

namespace accelviz::cli {

namespace {

namespace fs = std::filesystem;

struct RefitCliOptions {
  std::string scene;
  int frames = 30;
  std::string motion = "explode";
  float amplitude = 0.02f;
  double frame_step = 0.05;
  double rebuild_ratio = 0;
  std::string size = "320x240";
  unsigned threads = 0;
  std::uint64_t seed = 1;
  std::string out;
  bool force = false;
  StructureCli structure_opts;
};

/// Every name refit writes in its folder: the only files of the folder it refuses, replaces or removes.
OutputDirFiles refit_files() {
  return {"refit", {"refit.csv", "refit.json", "refit-sah.png", "refit-nodes.png", "refit-ms.png"}};
}

int run_refit(const RefitCliOptions& o, const GlobalOptions& global) {
  const ImageSize size = parse_size(o.size);
  if (!(o.amplitude >= 0) || !(o.amplitude <= 1000))
    throw UsageError("--amplitude must be a number from 0 to 1000 (times the scene's diagonal)");
  if (!std::isfinite(o.frame_step)) throw UsageError("--frame-step must be a finite number");
  if (!(o.rebuild_ratio == 0 || (o.rebuild_ratio >= 1 && std::isfinite(o.rebuild_ratio))))
    throw UsageError("--rebuild-ratio must be 0 (never) or a finite number >= 1");
  const OutputDirFiles files = refit_files();
  check_output_dir(o.out, files, o.force);  // refused before any work; created when the results are ready

  Progress progress(global.quiet);
  progress.begin("loading " + o.scene);
  const Scene scene = load_scene_noting_warnings(o.scene, global.quiet);
  require_flattened(scene, o.scene, "refit");
  progress.end(std::to_string(scene.triangles.size()) + " triangles");
  // The camera frames the rest pose; the motion is small against the scene, so it stays framed.
  const std::vector<Ray> rays =
      primary_rays(camera_for("", scene, size, /*has_camera_option=*/false), size.width, size.height);
  // The motion moves a vertex by up to 2 · amplitude · diagonal: near float's range that came out
  // as NaN SAH figures in the table and the CSV.
  if (const Aabb b = scene.bounds(); !b.is_empty()) {
    const glm::dvec3 lo(b.lo), hi(b.hi);
    const glm::dvec3 far = glm::max(glm::abs(lo), glm::abs(hi));
    const double reach = std::max({far.x, far.y, far.z}) + 2.0 * o.amplitude * glm::length(hi - lo);
    if (!(reach <= 1e37))
      throw std::runtime_error(o.scene + ": --amplitude " + number_text(o.amplitude) +
                               " would move vertices beyond float's range (to about " + number_text(reach) +
                               "); a smaller amplitude or scene");
  }

  RefitDecayOptions opts;
  opts.frames = o.frames;
  opts.amplitude = o.amplitude;
  opts.frame_step = o.frame_step;
  opts.rebuild_ratio = o.rebuild_ratio;
  opts.motion = parse_refit_motion(o.motion).value();  // CLI11 checked the name
  opts.seed = o.seed;
  opts.threads = o.threads;
  opts.bvh = o.structure_opts.to_options(o.threads, false).bvh;
  progress.begin("refitting " + count_of(static_cast<std::size_t>(o.frames), "frame"));
  const RefitDecayResult r = run_refit_decay(scene.triangles, rays, opts);
  progress.end(count_of(static_cast<std::size_t>(r.rebuilds), "rebuild"));

  // ---- files ----
  std::ostringstream csv;
  csv.precision(10);
  csv << "frame,refits_since_build,refit_ms,rebuild_ms,sah_refit,sah_fresh,ratio,nodes_per_ray_refit,"
         "prims_per_ray_refit,nodes_per_ray_fresh,prims_per_ray_fresh,rebuilt\n";
  nlohmann::json frames = nlohmann::json::array();
  for (const RefitFrame& f : r.frames) {
    csv << f.frame << ',' << f.refits_since_build << ',' << f.refit_ms << ',' << f.rebuild_ms << ',' << f.sah_refit
        << ',' << f.sah_fresh << ',' << f.ratio << ',' << f.nodes_per_ray_refit << ',' << f.prims_per_ray_refit << ','
        << f.nodes_per_ray_fresh << ',' << f.prims_per_ray_fresh << ',' << (f.rebuilt ? 1 : 0) << '\n';
    frames.push_back({{"frame", f.frame},
                      {"refits_since_build", f.refits_since_build},
                      {"refit_ms", f.refit_ms},
                      {"rebuild_ms", f.rebuild_ms},
                      {"sah_refit", f.sah_refit},
                      {"sah_fresh", f.sah_fresh},
                      {"ratio", f.ratio},
                      {"nodes_per_ray_refit", f.nodes_per_ray_refit},
                      {"prims_per_ray_refit", f.prims_per_ray_refit},
                      {"nodes_per_ray_fresh", f.nodes_per_ray_fresh},
                      {"prims_per_ray_fresh", f.prims_per_ray_fresh},
                      {"rebuilt", f.rebuilt}});
  }
  // All written to temporaries in DIR first; they take their names only once every one was written.
  OutputDirWriter out(o.out, files, o.force);
  out.add("refit.csv", csv.str());
  const nlohmann::json j = {{"scene", o.scene},
                            {"triangles", scene.triangles.size()},
                            {"frames", o.frames},
                            {"motion", "synthetic"},
                            {"motion_kind", o.motion},
                            {"scene_animations", scene.animations.size()},
                            {"amplitude_relative_to_diagonal", o.amplitude},
                            {"frame_step_periods", o.frame_step},
                            {"rebuild_ratio", o.rebuild_ratio},
                            {"rays", rays.size()},
                            {"seed", o.seed},
                            {"rebuilds", r.rebuilds},
                            {"per_frame", frames},
                            {"program", program_json()}};
  out.add("refit.json", json_text(j, 2) + "\n");

  ChartSeries refit{"refitted", {}, {}, {}, {214, 39, 40}, true, true, 2};
  ChartSeries fresh{"fresh build", {}, {}, {}, {31, 119, 180}, true, true, 2};
  ChartSeries nodes_refit = refit, nodes_fresh = fresh, ms_refit{"refit ms", {}, {}, {}, {214, 39, 40}, true, true, 2},
              ms_build{"rebuild ms", {}, {}, {}, {31, 119, 180}, true, true, 2};
  for (const RefitFrame& f : r.frames) {
    const double x = f.frame;
    refit.x.push_back(x), refit.y.push_back(f.sah_refit), refit.labels.push_back(f.rebuilt ? "rebuild" : "");
    fresh.x.push_back(x), fresh.y.push_back(f.sah_fresh);
    nodes_refit.x.push_back(x), nodes_refit.y.push_back(f.nodes_per_ray_refit);
    nodes_fresh.x.push_back(x), nodes_fresh.y.push_back(f.nodes_per_ray_fresh);
    if (f.frame == 0) continue;  // the rest pose: built, not refitted
    ms_refit.x.push_back(x), ms_refit.y.push_back(f.refit_ms);
    ms_build.x.push_back(x), ms_build.y.push_back(f.rebuild_ms);
  }
  const auto chart = [&](const std::string& name, const RgbImage& img) {
    out.add(name, encode_png(img, (fs::path(o.out) / name).string(), {{software_png_text()}}));
  };
  ChartOptions c;
  c.x_label = "frame";
  c.title = "sah cost: refit vs fresh build (" + o.motion + " motion)";
  c.y_label = "sah cost";
  chart("refit-sah.png", draw_chart(c, {refit, fresh}));
  c.title = "nodes visited per ray";
  c.y_label = "nodes/ray";
  chart("refit-nodes.png", draw_chart(c, {nodes_refit, nodes_fresh}));
  c.title = "refit vs rebuild time";
  c.y_label = "ms";
  chart("refit-ms.png", draw_chart(c, {ms_refit, ms_build}));
  out.commit();

  // ---- text ----
  std::printf("scene %s: %s; %s, amplitude %g of the diagonal; %s\n", o.scene.c_str(),
              count_of(scene.triangles.size(), "triangle").c_str(),
              count_of(static_cast<std::size_t>(o.frames), "frame").c_str(), o.amplitude,
              count_of(rays.size(), "primary ray").c_str());
  // The motion is this lab's own: say so, and where the scene's own animation is measured instead.
  if (scene.animations.empty())
    std::printf("motion: synthetic %s motion from the rest pose (frame 0; the scene itself is static)\n",
                o.motion.c_str());
  else
    std::printf(
        "motion: synthetic %s motion from the rest pose (frame 0); the scene's own %s %s not played here "
        "(`accelviz animate` plays %s)\n",
        o.motion.c_str(), count_of(scene.animations.size(), "animation").c_str(),
        scene.animations.size() == 1 ? "is" : "are", scene.animations.size() == 1 ? "it" : "them");
  std::printf("%6s %8s %10s %10s %10s %10s %8s %16s %16s %8s\n", "frame", "refits", "refit ms", "build ms", "SAH refit",
              "SAH fresh", "ratio", "refit nodes/ray", "fresh nodes/ray", "rebuilt");
  for (const RefitFrame& f : r.frames)
    std::printf("%6d %8d %10.3f %10.3f %10.3f %10.3f %8.3f %16.2f %16.2f %8s\n", f.frame, f.refits_since_build,
                f.refit_ms, f.rebuild_ms, f.sah_refit, f.sah_fresh, f.ratio, f.nodes_per_ray_refit,
                f.nodes_per_ray_fresh, f.rebuilt ? "yes" : "");
  std::printf(
      "refits: of the tree in use since it was built; ratio: SAH refit / SAH fresh; nodes/ray: nodes visited "
      "per primary ray%s\n",
      o.rebuild_ratio > 0.0 ? "; rebuilt: the ratio passed --rebuild-ratio, so the fresh tree replaced the "
                              "refitted one this row measured (the next frame refits it)"
                            : "");
  std::printf("rebuilds: %d; wrote %s\n", r.rebuilds, path_line(absolute_path(o.out)).c_str());
  return 0;
}

Command add_refit_command(CLI::App& parent, const GlobalOptions& global) {
  auto o = std::make_shared<RefitCliOptions>();
  CLI::App* sub = parent.add_subcommand(
      "refit", "Refit decay: BVH quality under a synthetic motion, refitted frame by frame against fresh builds");
  sub->add_option("SCENE", o->scene, "Scene file (.gltf, .glb, .obj) or builtin:NAME[?key=value&...]")->required();
  sub->add_option("--frames", o->frames, "Frames after the rest pose")->check(CLI::Range(1, 100000))->capture_default_str();
  sub->add_option("--motion", o->motion,
                  "explode: every triangle drifts rigidly on its own (the tree's grouping goes stale); wave: a "
                  "smooth bend (neighbours move alike); jitter: every vertex on its own (the mesh crumples)")
      ->check(CLI::IsMember({"explode", "wave", "jitter"}))
      ->capture_default_str();
  sub->add_option("--amplitude", o->amplitude, "Motion amplitude, relative to the scene diagonal (0 to 1000)")
      ->capture_default_str();
  sub->add_option("--frame-step", o->frame_step, "Time advance per frame, in motion periods")->capture_default_str();
  sub->add_option("--rebuild-ratio", o->rebuild_ratio,
                  "Rebuild when refit SAH / fresh SAH exceeds this (0: never)")
      ->capture_default_str();
  sub->add_option("--size", o->size, "Primary rays for the traversal figures: WxH")->check(size_validator())->capture_default_str();
  add_threads_option(sub, o->threads, "Build and trace threads (0: all)");
  sub->add_option("--seed", o->seed, "Seed of the motion")->capture_default_str();
  sub->add_option("--out,-o", o->out, "Output directory (created if missing)")->required();
  sub->add_flag("--force,-f", o->force,
                "Replace the refit files of an earlier run in DIR (only the names refit writes; the new set is "
                "written whole first)");
  o->structure_opts.add_to(sub, /*with_embree=*/false);  // it builds BVHs only
  return {sub, [o, &global] { return run_refit(*o, global); }};
}

const CommandRegistration register_refit{add_refit_command};

}  // namespace

}  // namespace accelviz::cli
