// accelviz sweep SCENE --param NAME=V1,V2 ... --out DIR: what accuracy costs
// in time. Thin over core/analysis/sweep.h: parse, load, make the ray set,
// run the sweep, then write sweep.csv, sweep.json and the charts, and print
// the Pareto-optimal settings and the best setting for a few ray budgets.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <thread>

#include "app/cli_common.h"
#include "core/analysis/chart.h"
#include "core/analysis/sweep.h"
#include "core/query/camera.h"
#include "core/scene/effects.h"
#include "core/util/huge_page_allocator.h"
#include "core/util/json_text.h"
#include "core/util/parallel.h"

namespace accelviz::cli {

namespace {

namespace fs = std::filesystem;

struct SweepCliOptions {
  std::string scene;
  std::string structure = "bvh";
  std::vector<std::string> params;
  std::string rays = "primary";
  std::string size = "640x480";
  int repeat = 3;
  int warmup = 1;
  unsigned threads = 0;
  double ray_budget = 1e6;
  std::string camera;
  std::uint64_t seed = 1;
  int edge_probes = 20000;
  std::string out;
  bool force = false;
};

const glm::u8vec3 kPalette[] = {{31, 119, 180}, {255, 127, 14}, {44, 160, 44}, {214, 39, 40}, {148, 103, 189},
                                {140, 86, 75},  {227, 119, 194}, {127, 127, 127}, {188, 189, 34}, {23, 190, 207}};

struct Figure {
  const char* key;
  const char* title;
  double (*get)(const SweepResult&, double budget);
};

const Figure kFigures[] = {
    {"sah_cost", "sah cost", [](const SweepResult& r, double) { return r.sah_cost; }},
    {"rays_per_s", "rays/s", [](const SweepResult& r, double) { return r.rays_per_s; }},
    {"nodes_per_ray", "nodes visited per ray", [](const SweepResult& r, double) { return r.nodes_per_ray; }},
    {"build_ms", "build ms", [](const SweepResult& r, double) { return r.build_ms; }},
    {"total_ms", "total ms for the ray budget", [](const SweepResult& r, double b) { return r.total_ms(b); }},
};

/// The structures sweep takes.

/// A figure's chart against one parameter: sweep-FIGURE-vs-PARAM.png.
std::string sweep_chart_name(std::string_view figure, std::string_view param) {
  return "sweep-" + std::string(figure) + "-vs-" + std::string(param) + ".png";
}

/// Every name a sweep writes in its folder (any structure, any parameter):
/// the only files of the folder it refuses, replaces or removes.
OutputDirFiles sweep_files() {
  OutputDirFiles files{"sweep", {"sweep.csv", "sweep.json", "sweep-pareto.png"}};
  for (const std::string& structure : sweep_structures())
    for (const std::string& param : sweep_param_names(structure))
      for (const Figure& f : kFigures)
        if (const std::string name = sweep_chart_name(f.key, param);
            std::find(files.names.begin(), files.names.end(), name) == files.names.end())
          files.names.push_back(name);
  return files;
}

/// (a) build time against trace time for the budget, Pareto front joined and labelled.
RgbImage pareto_chart(const std::vector<SweepResult>& results, const std::vector<std::size_t>& front, double budget,
                      const std::string& scene, bool leaks) {
  // With shared-edge probes the front is over build, trace and leaks: not a line in two dimensions, so
  // its points are not joined, and each label says its leaks.
  ChartSeries all{"other settings", {}, {}, {}, kPalette[0], false, true, 3};
  ChartSeries pf{
      leaks ? "pareto front (build, trace, leaks)" : "pareto front", {}, {}, {}, kPalette[3], !leaks, true, 4};
  const auto label = [&](const SweepResult& r) {
    return setting_label(r.setting) + (leaks ? " (" + count_of(r.edges.misses, "leak") + ")" : std::string());
  };
  for (std::size_t i = 0; i < results.size(); ++i) {
    if (std::find(front.begin(), front.end(), i) != front.end()) continue;
    all.x.push_back(results[i].build_ms);
    all.y.push_back(results[i].trace_ms(budget));
    // Label the dominated points too when there are few, so every dot is identifiable.
    if (results.size() <= 16) all.labels.push_back(label(results[i]));
  }
  if (all.x.empty()) all.name.clear();  // every setting is on the front: no legend entry without points
  for (std::size_t i : front) {
    pf.x.push_back(results[i].build_ms);
    pf.y.push_back(results[i].trace_ms(budget));
    pf.labels.push_back(label(results[i]));
  }
  ChartOptions o;
  o.width = 800;
  o.height = 520;
  o.title = "build vs trace: " + scene;
  o.x_label = "build ms";
  o.y_label = "trace ms for " + format_tick(budget) + " rays";
  o.y_from_zero = false;
  return draw_chart(o, {all, pf});
}

/// (b) one figure against parameter `p`: x = its values, one series per
/// combination of the other parameters.
RgbImage figure_chart(const std::vector<SweepResult>& results, const std::vector<SweepParam>& params, std::size_t p,
                      const Figure& fig, double budget) {
  std::map<std::string, ChartSeries> by_rest;
  std::vector<std::string> order;
  for (const SweepResult& r : results) {
    SweepSetting rest;
    std::size_t xi = 0;
    for (std::size_t k = 0; k < r.setting.size(); ++k) {
      if (k == p) {
        const auto& vals = params[p].values;
        xi = static_cast<std::size_t>(std::find(vals.begin(), vals.end(), r.setting[k].second) - vals.begin());
      } else {
        rest.push_back(r.setting[k]);
      }
    }
    const std::string name = rest.empty() ? "" : setting_label(rest);
    auto [it, inserted] = by_rest.try_emplace(name);
    if (inserted) {
      it->second.name = name;
      it->second.color = kPalette[order.size() % std::size(kPalette)];
      order.push_back(name);
    }
    it->second.x.push_back(static_cast<double>(xi));
    it->second.y.push_back(fig.get(r, budget));
  }
  // Values that are names (splitter, triangle test) have no order: their points are not joined.
  const bool named = std::none_of(params[p].values.begin(), params[p].values.end(), [](const std::string& v) {
    char* end = nullptr;
    std::strtod(v.c_str(), &end);
    return end != v.c_str() && *end == '\0';
  });
  std::vector<ChartSeries> series;
  for (const std::string& n : order) {
    series.push_back(by_rest[n]);
    if (named) series.back().lines = false;
  }
  ChartOptions o;
  o.title = std::string(fig.title) + " vs " + params[p].name;
  o.x_label = params[p].name;
  o.y_label = fig.key == std::string("total_ms") ? std::string("total ms, ") + format_tick(budget) + " rays" : fig.title;
  o.x_categories = params[p].values;
  return draw_chart(o, series);
}

}  // namespace

nlohmann::json sweep_result_json(const SweepResult& r, double budget) {
  nlohmann::json s = nlohmann::json::object();
  for (const auto& [k, v] : r.setting) s[k] = v;
  nlohmann::json j = {
      {"setting", s},
      {"label", setting_label(r.setting)},
      {"triangle_test", r.triangle_test},
      {"build_ms", r.build_ms},
      {"build_ms_runs", r.build_ms_runs},
      {"memory_bytes", r.memory_bytes},
      {"nodes", r.nodes},
      {"leaves", r.leaves},
      {"max_depth", r.max_depth},
      {"sah_cost", r.sah_cost > 0 ? nlohmann::json(r.sah_cost) : nlohmann::json(nullptr)},
      {"build_of", r.build_of.empty() ? nlohmann::json(nullptr) : nlohmann::json(r.build_of)},
      {"epo", r.epo >= 0 ? nlohmann::json(r.epo) : nlohmann::json(nullptr)},
      {"rays_per_s", r.rays_per_s},
      {"rays_per_s_runs", r.rays_per_s_runs},
      {"nodes_per_ray", r.nodes_per_ray},
      {"prims_per_ray", r.prims_per_ray},
      {"hit_fraction", r.hit_fraction},
      {"trace_ms_budget", r.trace_ms(budget)},
      {"total_ms_budget", r.total_ms(budget)},
      {"total_ms_1e6", r.total_ms(1e6)},
      {"total_ms_1e9", r.total_ms(1e9)},
  };
  if (r.edges.probes > 0)
    j["edges"] = {{"probes", r.edges.probes},
                  {"misses", r.edges.misses},
                  {"double_hits", r.edges.double_hits},
                  {"ray_double_hits", r.ray_double_hits}};
  return j;
}

namespace {

int run_sweep_command(const SweepCliOptions& o, const GlobalOptions& global) {
  use_fixed_malloc_thresholds();  // the settings' builds compare fairly from the first on
  // ---- everything that can be a usage error, before any long work ----
  if (o.params.empty()) throw UsageError("sweep: give at least one --param NAME=V1,V2,...");
  std::vector<SweepParam> params;
  std::vector<SweepSetting> settings;
  try {
    for (const std::string& p : o.params) params.push_back(parse_sweep_param(p));
    settings = expand_sweep(o.structure, params);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  const ImageSize size = parse_size(o.size);
  const RayKind kind = *parse_ray_kind(o.rays);
  const OutputDirFiles files = sweep_files();
  check_output_dir(o.out, files, o.force);  // refused before any work; created when the results are ready
  const unsigned threads = resolve_threads(o.threads);
  Progress progress(global.quiet);

  progress.begin("loading " + o.scene);
  const Scene scene = load_scene_noting_warnings(o.scene, global.quiet);
  require_flattened(scene, o.scene, "sweep");
  progress.end(std::to_string(scene.triangles.size()) + " triangles");

  progress.begin(std::string("making ") + o.rays + " rays");
  const Camera camera = camera_for(o.camera, scene, size);
  bool synthetic = false;  // shadow rays to synthetic_light(): the scene has no lights
  const std::vector<Ray> rays =
      sweep_ray_set(scene, camera, size.width, size.height, kind, o.seed, o.threads, &synthetic);
  progress.end(std::to_string(rays.size()) + " rays");

  // Shared-edge probes only when the triangle test is swept: they need an edge map of the whole mesh.
  std::vector<EdgeProbe> probes;
  bool sweeps_triangle = false;
  for (const SweepParam& p : params) sweeps_triangle |= p.name == "triangle";
  if (sweeps_triangle && o.edge_probes > 0) {
    progress.begin("shared-edge probes");
    probes = shared_edge_probes(scene.triangles, static_cast<std::size_t>(o.edge_probes), o.seed);
    progress.end(std::to_string(probes.size()) + " probes");
  }

  SweepConfig config;
  config.structure = o.structure;
  config.base.bvh.threads = o.threads;
  config.base.threads = o.threads;
  config.repeat = o.repeat;
  config.warmup = o.warmup;
  config.threads = o.threads;
  config.ray_budget = o.ray_budget;
  config.progress = progress.callback();  // inside each setting: its label (begin below) and a percentage
  std::vector<SweepResult> results;
  results.reserve(settings.size());
  for (std::size_t i = 0; i < settings.size(); ++i) {
    progress.begin("setting " + std::to_string(i + 1) + "/" + std::to_string(settings.size()) + ": " +
                   setting_label(settings[i]));
    // A setting that differs from an earlier one only in the triangle test builds the same tree: its build is
    // not measured again (a second measurement would report the noise as a cost).
    const auto same = earlier_same_build(settings, i);
    results.push_back(
        measure_sweep_setting(scene.triangles, rays, probes, config, settings[i], same ? &results[*same] : nullptr));
    char buf[96];
    std::snprintf(buf, sizeof buf, "build %.1f ms, %.3g rays/s", results.back().build_ms, results.back().rays_per_s);
    progress.end(buf);
  }

  // ---- analysis ----
  const std::vector<std::size_t> front = pareto_front(sweep_points(results, o.ray_budget));
  std::vector<double> budgets{1e6, 1e9};
  if (o.ray_budget != 1e6 && o.ray_budget != 1e9) budgets.push_back(o.ray_budget);

  // ---- files ----
  // All written to temporaries in DIR first; they take their names only once every one was written.
  OutputDirWriter out(o.out, files, o.force);
  out.add("sweep.csv", sweep_csv(results, o.ray_budget));
  nlohmann::json j;
  j["machine"] = machine_json(threads);
  j["scene"] = o.scene;
  j["triangles"] = scene.triangles.size();
  j["structure"] = o.structure;
  j["rays"] = {{"kind", o.rays}, {"count", rays.size()}, {"size", {size.width, size.height}}, {"seed", o.seed}};
  if (kind == RayKind::shadow) j["rays"]["synthetic_light"] = synthetic;
  j["repeat"] = o.repeat;
  j["warmup"] = o.warmup;
  j["ray_budget"] = o.ray_budget;
  j["params"] = nlohmann::json::object();
  for (const SweepParam& p : params) j["params"][p.name] = p.values;
  j["results"] = nlohmann::json::array();
  for (const SweepResult& r : results) j["results"].push_back(sweep_result_json(r, o.ray_budget));
  j["pareto_front"] = nlohmann::json::array();
  for (std::size_t i : front) j["pareto_front"].push_back(setting_label(results[i].setting));
  j["best_for_budget"] = nlohmann::json::array();
  for (double b : budgets) {
    const SweepResult& r = results[best_for_budget(results, b)];
    nlohmann::json e = {{"rays", b}, {"setting", setting_label(r.setting)}, {"total_ms", r.total_ms(b)}};
    if (!probes.empty()) {
      e["edge_leaks"] = r.edges.misses;
      const auto clean = best_without_leaks(results, b);
      e["best_without_leaks"] = clean ? nlohmann::json{{"setting", setting_label(results[*clean].setting)},
                                                       {"total_ms", results[*clean].total_ms(b)}}
                                      : nlohmann::json(nullptr);
    }
    j["best_for_budget"].push_back(e);
  }
  const TimingScatter scatter = timing_scatter(results);
  j["timing_scatter"] = {{"rays_per_s", scatter.rays_per_s}, {"build_ms", scatter.build_ms}};
  out.add("sweep.json", json_text(j, 2) + "\n");

  std::vector<std::string> charts;
  auto chart = [&](const std::string& name, const RgbImage& img) {
    out.add(name, encode_png(img, (fs::path(o.out) / name).string(), {{software_png_text()}}));
    charts.push_back(name);
  };
  chart("sweep-pareto.png", pareto_chart(results, front, o.ray_budget, o.scene, !probes.empty()));
  for (std::size_t p = 0; p < params.size(); ++p)
    for (const Figure& f : kFigures) {
      if (f.key == std::string("sah_cost") && o.structure != "bvh" && o.structure != "kdtree" && o.structure != "octree")
        continue;  // grids and voxels report no SAH cost
      chart(sweep_chart_name(f.key, params[p].name), figure_chart(results, params, p, f, o.ray_budget));
    }
  out.commit();

  // ---- text ----
  std::printf("scene %s: %s; %s, %zu %s rays; %s; medians of %d; ray budget %g\n", o.scene.c_str(),
              count_of(scene.triangles.size(), "triangle").c_str(), o.structure.c_str(), rays.size(), o.rays.c_str(),
              count_of(threads, "thread").c_str(), o.repeat, o.ray_budget);
  if (kind == RayKind::shadow && synthetic) {
    const glm::vec3 p = synthetic_light(scene).position;
    std::printf("the scene has no lights: shadow rays aim at a synthetic point light at (%g, %g, %g)\n", p.x, p.y, p.z);
  }
  std::printf("%-32s %10s %10s %8s %10s %10s %12s %12s", "setting", "build ms", "memory", "SAH", "nodes/ray",
              "prims/ray", "Mrays/s", "total ms");
  if (!probes.empty()) std::printf(" %12s %12s", "edge leaks", "rays hit 2x");
  std::printf("\n");
  for (const SweepResult& r : results) {
    char sah[32] = "n/a";  // grids and voxels report no SAH cost
    if (r.sah_cost > 0) std::snprintf(sah, sizeof sah, "%.3f", r.sah_cost);
    std::printf("%-32s %10.2f %10s %8s %10.2f %10.2f %12.3f %12.2f", setting_label(r.setting).c_str(), r.build_ms,
                format_bytes(r.memory_bytes).c_str(), sah, r.nodes_per_ray, r.prims_per_ray, r.rays_per_s / 1e6,
                r.total_ms(o.ray_budget));
    if (!probes.empty())
      std::printf(" %5llu/%llu", static_cast<unsigned long long>(r.edges.misses),
                  static_cast<unsigned long long>(r.edges.probes));
    if (!probes.empty()) std::printf(" %12llu", static_cast<unsigned long long>(r.ray_double_hits));
    std::printf("\n");
  }
  for (const SweepResult& r : results)
    if (!r.build_of.empty()) {
      std::printf(
          "settings that differ only in the triangle test share one tree: its build figures are measured "
          "once (e.g. %s: those of %s)\n",
          setting_label(r.setting).c_str(), r.build_of.c_str());
      break;
    }
  std::printf("\nPareto-optimal (build ms, trace ms for %g rays%s):\n", o.ray_budget,
              probes.empty() ? "" : ", edge leaks");
  for (std::size_t i : front) {
    std::printf("  %-32s build %.2f ms, trace %.2f ms", setting_label(results[i].setting).c_str(), results[i].build_ms,
                results[i].trace_ms(o.ray_budget));
    if (!probes.empty()) std::printf(", %llu leaks", static_cast<unsigned long long>(results[i].edges.misses));
    std::printf("\n");
  }
  for (double b : {1e6, 1e9}) {
    const SweepResult& r = results[best_for_budget(results, b)];
    std::printf("best for %g rays: %s (total %.1f ms)", b, setting_label(r.setting).c_str(), r.total_ms(b));
    // The fastest setting may leak through shared edges: name the fastest that does not.
    if (!probes.empty() && r.edges.misses > 0) {
      std::printf("; it leaks through %llu of %llu shared-edge probes", static_cast<unsigned long long>(r.edges.misses),
                  static_cast<unsigned long long>(r.edges.probes));
      if (const auto clean = best_without_leaks(results, b))
        std::printf("; without leaks: %s (total %.1f ms)", setting_label(results[*clean].setting).c_str(),
                    results[*clean].total_ms(b));
    }
    std::printf("\n");
  }
  // Times are measurements: say how far one setting's own runs lie apart, and when other work shares the cores.
  if (scatter.rays_per_s > 0.1 || scatter.build_ms > 0.1)
    std::printf(
        "note: one setting's own runs lie up to %.0f %% apart (rays/s) and %.0f %% (build): differences in "
        "time below that are no ranking; SAH, nodes and tests per ray do not scatter\n",
        100.0 * scatter.rays_per_s, 100.0 * scatter.build_ms);
  // (The run's own threads count in the load: more than one above the hardware threads is others' work.)
  if (const double load = load_average(); load > static_cast<double>(std::thread::hardware_concurrency()) + 1.0)
    std::printf("note: load average %.2f on %u hardware threads: other work shared the cores while this was timed\n",
                load, std::thread::hardware_concurrency());
  std::printf("wrote %s: sweep.csv, sweep.json and %zu charts\n", path_line(absolute_path(o.out)).c_str(),
              charts.size());
  return 0;
}

Command add_sweep_command(CLI::App& parent, const GlobalOptions& global) {
  auto o = std::make_shared<SweepCliOptions>();
  CLI::App* sub = parent.add_subcommand(
      "sweep", "Sweep structure parameters: build time, memory, SAH, rays/s and total time for a ray budget per "
               "setting, the Pareto front, CSV/JSON and charts");
  sub->add_option("SCENE", o->scene, "Scene file (.gltf, .glb, .obj) or builtin:NAME[?key=value&...]")->required();
  sub->add_option("--structure,-s", o->structure, "Structure to sweep: bvh, kdtree, grid, octree, voxels")
      ->check(CLI::IsMember(sweep_structures()))
      ->capture_default_str();
  sub->add_option("--param,-p", o->params,
                  "NAME=V1,V2,... (repeatable; the cartesian product is swept). bvh: buckets (2..256 or exact), "
                  "splitter (median,binned,exact,lbvh), leaf, ctrav, cisect; kdtree: depth, ctrav, cisect, leaf, "
                  "mailbox (on,off); grid: lambda, res (NXxNYxNZ); octree: depth, leaf; voxels: level; all: "
                  "triangle (watertight,fast)")
      ->required();
  sub->add_option("--rays", o->rays, "Ray set: primary, diffuse or shadow")
      ->check(CLI::IsMember({"primary", "diffuse", "shadow"}))
      ->capture_default_str();
  sub->add_option("--size", o->size, "Primary rays: one per pixel of a WxH image")->check(size_validator())->capture_default_str();
  sub->add_option("--repeat,-n", o->repeat, "Builds and timed passes per setting (medians)")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  sub->add_option("--warmup", o->warmup, "Untimed builds and passes per setting before the timed ones")
      ->check(CLI::Range(0, 100))
      ->capture_default_str();
  add_threads_option(sub, o->threads, "Build and trace threads (0: all hardware threads)");
  sub->add_option("--ray-budget", o->ray_budget, "Rays N of total time = build + N / (rays/s)")
      ->check(finite_positive())
      ->capture_default_str();
  sub->add_option("--camera", o->camera, "View: ex,ey,ez,tx,ty,tz[,fovdeg] or gltf:N");
  sub->add_option("--seed", o->seed, "Seed of diffuse directions and edge probes")->capture_default_str();
  sub->add_option("--edge-probes", o->edge_probes,
                  "When triangle is swept: rays aimed at shared-edge midpoints, to count leaks")
      ->check(CLI::Range(0, 10000000))
      ->capture_default_str();
  sub->add_option("--out,-o", o->out, "Output directory (created if missing)")->required();
  sub->add_flag("--force,-f", o->force,
                "Replace the sweep files of an earlier run in DIR (only the names sweep writes; the new set is "
                "written whole first)");
  return {sub, [o, &global] { return run_sweep_command(*o, global); }};
}

const CommandRegistration register_sweep{add_sweep_command};

}  // namespace

}  // namespace accelviz::cli
