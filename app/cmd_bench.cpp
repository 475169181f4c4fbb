// accelviz bench SCENE: build and query figures of one or more structures on
// the same ray sets (primary, diffuse, shadow), as medians of repeated runs,
// quoted against Embree when it is among the structures.
//
// Protocol (docs/cli.md): the ray sets are generated once, from the first
// structure's primary hits. `repeat` rounds that build every structure once,
// in turn (median build time; the other build figures are deterministic and
// come from the last build); per ray set, closest-hit and any-hit throughput
// on one thread and on all threads, each the median of `repeat` timed passes
// without counters, the structures again taking turns within each round so
// that a change of machine load falls on all of them alike; for the
// structures that walk packets (Bvh, Embree) also closest and any hit in
// packets of eight consecutive rays on one thread; then one
// instrumented pass for the mean node visits and primitive tests per ray,
// kept out of the timings. `warmup` untimed rounds (builds, passes) may come
// before the timed ones.
#include <algorithm>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>

#include "app/cli_common.h"
#include "core/analysis/heatmap.h"
#include "core/query/batch.h"
#include "core/query/camera.h"
#include "core/query/ray_sets.h"
#include "core/scene/effects.h"
#include "core/util/json_text.h"
#include "core/util/parallel.h"

namespace accelviz::cli {

namespace {

struct BenchOptions {
  std::string scene;
  std::vector<std::string> structures;
  std::string rays = "all";
  std::string size = "800x600";
  int repeat = 5;
  int warmup = 0;  ///< untimed rounds before the timed ones (builds and every figure)
  unsigned threads = 0;
  bool json = false;
  std::string camera;
  std::uint64_t seed = 1;
  std::string triangle_test = "watertight";
  bool no_epo = false;
  StructureCli structure_opts;
};

struct RaySet {
  std::string name;
  std::vector<Ray> rays;
};

struct QueryFigures {
  double closest_1t = 0, closest_nt = 0, any_1t = 0, any_nt = 0;   ///< Mrays/s, medians
  bool packets = false;                                            ///< the structure walks packets (has_packets)
  double closest_packet_1t = 0, any_packet_1t = 0;                 ///< Mrays/s in packets of 8, one thread, medians
  double closest_nodes = 0, closest_prims = 0, closest_boxes = 0;  ///< per ray, instrumented pass
  double any_nodes = 0, any_prims = 0, any_boxes = 0;
  double hit_fraction = 0, occluded_fraction = 0;
};

struct StructureResult {
  std::string name;
  std::string refused;  ///< why the structure was not built (Embree refused the scene); empty when it was
  /// Ray sets the structure refused a ray of (Embree's limits), with the first ray and why; not measured.
  std::vector<std::pair<std::string, std::string>> refused_sets;
  std::vector<double> build_ms;
  BuildStats stats;                            ///< of the last build
  std::optional<EmbreeBvhFigures> embree_bvh;  ///< bvh only: Embree's binary rtcBuildBVH on the same input
  std::vector<std::pair<std::string, QueryFigures>> queries;
};

/// A rate in Mrays/s with two decimals, or three significant digits below
/// 0.1: a grid's 0.0035 on a stadium read "0.00", as if nothing were traced.
std::string rate_text(double mrays_per_s) {
  char text[32];
  // "%#.3g": the zeros kept (0.000500, not 0.0005, which read as one digit).
  std::snprintf(text, sizeof text, mrays_per_s > 0.0 && mrays_per_s < 0.1 ? "%#.3g" : "%.2f", mrays_per_s);
  return text;
}

double mrays(std::size_t n, double ms) {
  return ms > 0.0 ? static_cast<double>(n) / (ms * 1e3) : 0.0;
}

/// One timed pass of every structure in turn, `repeat` rounds; returns each
/// structure's median Mrays/s. Rounds alternate the structures so that a
/// change of machine load during the run falls on all of them alike.
template <typename Pass>
std::vector<double> timed_medians_in_turns(std::size_t structures, int warmup, int repeat, std::size_t n, Pass&& pass) {
  for (int r = 0; r < warmup; ++r)
    for (std::size_t i = 0; i < structures; ++i) pass(i);
  std::vector<std::vector<double>> v(structures);
  for (int r = 0; r < repeat; ++r)
    for (std::size_t i = 0; i < structures; ++i) {
      const auto t0 = Clock::now();
      pass(i);
      v[i].push_back(mrays(n, ms_since(t0)));
    }
  std::vector<double> out;
  for (std::vector<double>& runs : v) out.push_back(median(std::move(runs)));
  return out;
}

/// Throughput of every structure on one ray set, the structures in turns
/// (timed_medians_in_turns) for each of the four figures.
std::vector<QueryFigures> measure_in_turns(const std::vector<const Accelerator*>& accels, const std::vector<Ray>& rays,
                                           const QueryOptions& q, unsigned all, int warmup, int repeat,
                                           Progress& progress, const std::string& label) {
  std::vector<QueryFigures> f(accels.size());
  const std::size_t n = rays.size();
  if (n == 0) return f;
  std::vector<Hit> hits(n);
  std::vector<std::uint8_t> occluded(n);
  const auto figure = [&](const std::string& what, double QueryFigures::*field, auto&& pass) {
    progress.begin(label + ": " + what);
    const std::vector<double> m = timed_medians_in_turns(accels.size(), warmup, repeat, n, pass);
    for (std::size_t i = 0; i < f.size(); ++i) f[i].*field = m[i];
    progress.end();
  };
  const std::string threads = all > 1 ? count_of(all, "thread") : "all threads (1)";
  figure("closest hit, 1 thread", &QueryFigures::closest_1t,
         [&](std::size_t i) { trace_closest(*accels[i], rays, hits, q, 1u); });
  figure("closest hit, " + threads, &QueryFigures::closest_nt,
         [&](std::size_t i) { trace_closest(*accels[i], rays, hits, q, all); });
  figure("any hit, 1 thread", &QueryFigures::any_1t,
         [&](std::size_t i) { trace_any(*accels[i], rays, occluded, q, 1u); });
  figure("any hit, " + threads, &QueryFigures::any_nt,
         [&](std::size_t i) { trace_any(*accels[i], rays, occluded, q, all); });
  // Packets of eight consecutive rays, one thread, for the structures that
  // walk packets (the others would only repeat their per-ray figures).
  std::vector<const Accelerator*> with_packets;
  std::vector<std::size_t> index;
  for (std::size_t i = 0; i < accels.size(); ++i)
    if (accels[i]->has_packets()) {
      with_packets.push_back(accels[i]);
      index.push_back(i);
      f[i].packets = true;
    }
  if (!with_packets.empty()) {
    const auto packet_figure = [&](const std::string& what, double QueryFigures::*field, auto&& pass) {
      progress.begin(label + ": " + what);
      const std::vector<double> m = timed_medians_in_turns(with_packets.size(), warmup, repeat, n, pass);
      for (std::size_t k = 0; k < index.size(); ++k) f[index[k]].*field = m[k];
      progress.end();
    };
    packet_figure("closest hit, packets of 8, 1 thread", &QueryFigures::closest_packet_1t,
                  [&](std::size_t k) { trace_closest_packets(*with_packets[k], rays, hits, q, BatchOptions{1u}); });
    packet_figure("any hit, packets of 8, 1 thread", &QueryFigures::any_packet_1t,
                  [&](std::size_t k) { trace_any_packets(*with_packets[k], rays, occluded, q, BatchOptions{1u}); });
  }
  return f;
}

/// One instrumented pass per query kind for the mean counters per ray, kept
/// out of the timings.
void count_per_ray(const Accelerator& accel, const std::vector<Ray>& rays, const QueryOptions& q, unsigned all,
                   QueryFigures& f) {
  const std::size_t n = rays.size();
  if (n == 0) return;
  std::vector<Hit> hits(n);
  std::vector<std::uint8_t> occluded(n);
  std::vector<RayStats> stats(n);
  trace_closest(accel, rays, hits, q, all, stats);
  double nodes = 0, prims = 0, boxes = 0, hit_count = 0;
  for (std::size_t i = 0; i < n; ++i) {
    nodes += stats[i].nodes_visited;
    prims += stats[i].prim_tests;
    boxes += stats[i].box_tests;
    hit_count += hits[i].valid();
  }
  f.closest_nodes = nodes / n;
  f.closest_prims = prims / n;
  f.closest_boxes = boxes / n;
  f.hit_fraction = hit_count / n;
  trace_any(accel, rays, occluded, q, all, stats);
  nodes = prims = boxes = hit_count = 0;
  for (std::size_t i = 0; i < n; ++i) {
    nodes += stats[i].nodes_visited;
    prims += stats[i].prim_tests;
    boxes += stats[i].box_tests;
    hit_count += occluded[i];
  }
  f.any_nodes = nodes / n;
  f.any_prims = prims / n;
  f.any_boxes = boxes / n;
  f.occluded_fraction = hit_count / n;
}

/// The figures of one ray set; without per-ray counters (Embree) the per-ray
/// counts are null, as sweep writes a figure a structure does not have (0
/// read as the cheapest).
nlohmann::json query_json(const QueryFigures& f, bool counters, bool prims_counted) {
  nlohmann::json j = {
      {"closest_mrays_1t", f.closest_1t},
      {"closest_mrays_nt", f.closest_nt},
      {"any_mrays_1t", f.any_1t},
      {"any_mrays_nt", f.any_nt},
      {"closest_nodes_per_ray", f.closest_nodes},
      {"closest_prims_per_ray", f.closest_prims},
      {"closest_boxes_per_ray", f.closest_boxes},
      {"any_nodes_per_ray", f.any_nodes},
      {"any_prims_per_ray", f.any_prims},
      {"any_boxes_per_ray", f.any_boxes},
      {"hit_fraction", f.hit_fraction},
      {"occluded_fraction", f.occluded_fraction},
  };
  if (!counters)
    for (const char* k : {"closest_nodes_per_ray", "closest_prims_per_ray", "closest_boxes_per_ray",
                          "any_nodes_per_ray", "any_prims_per_ray", "any_boxes_per_ray"})
      j[k] = nullptr;
  if (!prims_counted)  // the voxels test no triangles (a hit is a voxel)
    for (const char* k : {"closest_prims_per_ray", "any_prims_per_ray"}) j[k] = nullptr;
  if (f.packets) {
    j["closest_packet_mrays_1t"] = f.closest_packet_1t;
    j["any_packet_mrays_1t"] = f.any_packet_1t;
  }
  return j;
}

double ratio(double ours, double theirs) {
  return theirs > 0.0 ? ours / theirs : 0.0;
}

/// Bench-only rows: Embree at a fixed build quality, beside the plain
/// "embree" row (which follows --embree-quality, medium by default).
constexpr const char* kEmbreeQualityRows[] = {"embree-low", "embree-medium", "embree-high"};

std::vector<std::string> bench_structure_names() {
  std::vector<std::string> names = structure_names();
  if (kHaveEmbree)
    for (const char* n : kEmbreeQualityRows) names.emplace_back(n);
  return names;
}

/// "ray I: why" for the first ray of `rays` that `accel` cannot take (Embree's
/// limits, ray_refusals); empty when it takes every ray.
std::string first_refused_ray(const Accelerator& accel, const std::vector<Ray>& rays) {
  const RayRefusals r = ray_refusals(accel, rays);
  return r.count > 0 ? "ray " + std::to_string(r.first) + ": " + r.reason : std::string();
}

/// Embree refuses scenes it cannot hold (a vertex beyond its range, its
/// build leaves such triangles out): that is a refusal of the structure, not
/// an error of the run.
bool refuses_scenes(const std::string& name) {
  return name == "embree" || name.starts_with("embree-");
}

std::unique_ptr<Accelerator> build_bench_structure(const std::string& name, std::span<const Triangle> tris,
                                                   const StructureOptions& so, const ProgressCallback& cb) {
  if (name.starts_with("embree-")) {
    StructureOptions o = so;
    o.embree.quality = parse_embree_quality(std::string_view(name).substr(7)).value_or(EmbreeQuality::medium);
    return build_accelerator("embree", tris, o, cb);
  }
  return build_accelerator(name, tris, so, cb);
}

int run_bench(BenchOptions o, const GlobalOptions& global) {
  // A structure named in --structure that refuses the scene or rays makes the
  // run exit 1 (after the others are measured); the default list's Embree does not.
  const bool named_by_user = !o.structures.empty();
  std::vector<std::string> listed;  // each -s value split at its commas (name_list_problem checked them)
  for (const std::string& value : o.structures)
    for (std::string& item : comma_items(value)) listed.push_back(std::move(item));
  o.structures = std::move(listed);
  if (o.structures.empty())
    o.structures = kHaveEmbree ? std::vector<std::string>{"bvh", "embree"} : std::vector<std::string>{"bvh"};
  if (o.repeat < 1) throw UsageError("--repeat must be at least 1");
  o.structure_opts.say_unused(o.structures, false, global.quiet);
  // Each structure is one row: a name twice would build and time it twice.
  for (std::size_t i = 0; i < o.structures.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j)
      if (o.structures[j] == o.structures[i])
        throw UsageError("--structure: '" + o.structures[i] + "' is listed twice");
  }
  const ImageSize size = parse_size(o.size);
  const unsigned all = resolve_threads(o.threads);
  QueryOptions q;
  q.triangle_test = parse_triangle_test(o.triangle_test);
  Progress progress(global.quiet);

  progress.begin("loading " + o.scene);
  const Scene scene = load_scene_noting_warnings(o.scene, global.quiet);
  progress.end(count_of(scene.triangles.size(), "triangle"));
  // The level the scene calls for: one note for the list (its tlas, or its first structure).
  if (!global.quiet) {
    const bool has_tlas = std::find(o.structures.begin(), o.structures.end(), "tlas") != o.structures.end();
    if (const std::string note = level_note(scene, has_tlas ? "tlas" : o.structures.front()); !note.empty())
      std::fprintf(stderr, "accelviz: note: %s\n", note.c_str());
  }
  StructureOptions so = o.structure_opts.to_options(o.threads, /*compute_epo=*/!o.no_epo);
  so.scene = &scene;  // "tlas" builds its two levels from the scene's meshes and instances

  // ---- ray sets, from the primary hits of the first structure that takes the scene and the primary rays ----
  const Camera camera = camera_for(o.camera, scene, size);
  std::vector<RaySet> sets;
  sets.push_back({"primary", primary_rays(camera, size.width, size.height)});
  bool synthetic_light = false;
  std::optional<glm::vec3> synthetic_position;
  const bool want_diffuse = o.rays == "all" || o.rays == "diffuse";
  const bool want_shadow = o.rays == "all" || o.rays == "shadow";
  if (want_diffuse || want_shadow) {
    StructureOptions quick = so;
    quick.bvh.compute_epo = false;
    std::unique_ptr<Accelerator> ref;
    std::string first_refusal;
    for (const std::string& name : o.structures) {
      progress.begin("primary hits for the secondary rays (" + name + ")");
      try {
        ref = build_bench_structure(name, scene.triangles, quick, {});
      } catch (const std::runtime_error& e) {
        if (!refuses_scenes(name)) throw;
        if (first_refusal.empty()) first_refusal = e.what();
        progress.end("refused");
        continue;
      }
      if (const std::string refused = first_refused_ray(*ref, sets[0].rays); !refused.empty()) {
        if (first_refusal.empty()) first_refusal = name + ": primary rays: " + refused;
        ref.reset();
        progress.end("refused");
        continue;
      }
      break;
    }
    if (!ref) throw std::runtime_error(first_refusal);  // no structure takes the scene and its primary rays
    std::vector<Hit> hits(sets[0].rays.size());
    trace_closest(*ref, sets[0].rays, hits, q, all);
    progress.end();
    if (want_diffuse) sets.push_back({"diffuse", diffuse_rays(scene.triangles, sets[0].rays, hits, o.seed)});
    if (want_shadow) {
      const std::vector<Light> lights = shadow_lights(scene, true);
      if (casting_lights(scene).empty()) {  // a stand-in (no light, or none that gives light), reported
        synthetic_light = true;
        synthetic_position = lights[0].position;
      }
      sets.push_back({"shadow", shadow_rays(scene.triangles, sets[0].rays, hits, lights)});
    }
  }
  if (o.rays != "all" && o.rays != "primary") sets.erase(sets.begin());
  if (synthetic_light && !global.quiet)
    std::fprintf(stderr,
                 "accelviz: %s has no lights%s: shadow rays aim at a synthetic point light at (%g, %g, %g) "
                 "(benchmark only)\n",
                 o.scene.c_str(), scene.lights.empty() ? "" : " that give light (intensity or colour 0)",
                 synthetic_position->x, synthetic_position->y, synthetic_position->z);

  // ---- builds: each round builds every structure once, in turn ----
  const std::size_t count = o.structures.size();
  std::vector<StructureResult> results(count);
  std::vector<std::unique_ptr<Accelerator>> accels(count);
  for (int k = -o.warmup; k < o.repeat; ++k)
    for (std::size_t i = 0; i < count; ++i) {
      const std::string& name = o.structures[i];
      results[i].name = name;
      if (!results[i].refused.empty()) continue;
      const std::string round = k < 0 ? "warm-up " + std::to_string(k + o.warmup + 1) + "/" + std::to_string(o.warmup)
                                      : std::to_string(k + 1) + "/" + std::to_string(o.repeat);
      progress.begin("building " + name + " (" + round + ")");
      accels[i].reset();  // never two copies of one structure in memory
      try {
        accels[i] = build_bench_structure(name, scene.triangles, so, progress.callback());
      } catch (const std::runtime_error& e) {
        if (!refuses_scenes(name)) throw;
        results[i].refused = without_name_prefix(e.what(), "embree");  // the others are still measured
        progress.end("refused");
        continue;
      }
      if (k >= 0) results[i].build_ms.push_back(accels[i]->build_stats().build_ms);
      progress.end(std::to_string(static_cast<long long>(accels[i]->build_stats().build_ms)) + " ms");
    }
  bool any_built = false;
  for (const StructureResult& r : results) any_built = any_built || r.refused.empty();
  if (!any_built) throw std::runtime_error("embree: " + results.front().refused);
  for (std::size_t i = 0; i < count; ++i) {
    StructureResult& r = results[i];
    if (!r.refused.empty()) continue;
    r.stats = accels[i]->build_stats();
#ifdef ACCELVIZ_HAVE_EMBREE
    if (r.name == "bvh" && !scene.triangles.empty()) {
      progress.begin("Embree rtcBuildBVH binary tree for the SAH comparison");
      r.embree_bvh = embree_binary_bvh_sah(scene.triangles, so.bvh.cost_traversal, so.bvh.cost_intersect, o.threads,
                                           so.bvh.max_leaf_size, std::min(so.bvh.leaf_size_cap, 32));
      progress.end();
    }
#endif
  }

  // ---- queries: per ray set and figure, the structures in turns ----
  // A structure that refuses a ray of a set (Embree's limits) is not measured
  // on that set: the others' figures stay on the same rays.
  for (const RaySet& set : sets) {
    std::vector<const Accelerator*> taking;
    std::vector<std::size_t> index;
    for (std::size_t i = 0; i < count; ++i) {
      if (!accels[i]) continue;
      if (std::string refused = first_refused_ray(*accels[i], set.rays); !refused.empty()) {
        results[i].refused_sets.push_back({set.name, std::move(refused)});
        continue;
      }
      taking.push_back(accels[i].get());
      index.push_back(i);
    }
    std::vector<QueryFigures> f = measure_in_turns(taking, set.rays, q, all, o.warmup, o.repeat, progress, set.name);
    for (std::size_t k = 0; k < index.size(); ++k) {
      const std::size_t i = index[k];
      progress.begin(o.structures[i] + " " + set.name + ": counting pass");
      count_per_ray(*accels[i], set.rays, q, all, f[k]);
      progress.end();
      results[i].queries.push_back({set.name, f[k]});
    }
  }
  bool refusals = false;
  for (const StructureResult& r : results) refusals = refusals || !r.refused.empty() || !r.refused_sets.empty();
  const int exit_code = refusals && named_by_user ? 1 : 0;

  const StructureResult* embree = nullptr;
  for (const StructureResult& r : results)
    if (r.name == "embree" && r.refused.empty()) embree = &r;
  /// The figures of `r` on the set named `set`, or null when it was not measured there.
  const auto figures_on = [](const StructureResult& r, const std::string& set) -> const QueryFigures* {
    for (const auto& [name, f] : r.queries)
      if (name == set) return &f;
    return nullptr;
  };

  // ---- JSON ----
  nlohmann::json j;
  j["scene"] = o.scene;
  j["triangles"] = scene.triangles.size();
  j["threads"] = all;
  j["repeat"] = o.repeat;
  j["warmup"] = o.warmup;
  j["size"] = {size.width, size.height};
  j["triangle_test"] = o.triangle_test;
  if (kHaveEmbree) {
    j["embree_robust"] = so.embree.robust;
    j["embree_isa"] = std::string(embree_isa_name(so.embree.isa));
  }
  j["ray_sets"] = nlohmann::json::object();
  for (const RaySet& set : sets) {
    j["ray_sets"][set.name] = {{"rays", set.rays.size()}};
    if (set.name == "shadow") {
      j["ray_sets"]["shadow"]["synthetic_light"] = synthetic_light;
      j["ray_sets"]["shadow"]["lights"] = synthetic_light ? 1 : scene.lights.size();
    }
    if (set.name == "diffuse") j["ray_sets"]["diffuse"]["seed"] = o.seed;
  }
  j["structures"] = nlohmann::json::array();
  j["not_measured"] = nlohmann::json::array();
  for (const StructureResult& r : results) {
    if (!r.refused.empty()) j["not_measured"].push_back({{"structure", r.name}, {"reason", r.refused}});
    for (const auto& [set, why] : r.refused_sets)
      j["not_measured"].push_back({{"structure", r.name}, {"ray_set", set}, {"reason", why}});
  }
  for (const StructureResult& r : results) {
    if (!r.refused.empty()) continue;
    nlohmann::json s;
    s["name"] = r.name;
    s["build"] = {
        {"build_ms", median(r.build_ms)},       {"build_ms_runs", r.build_ms},
        {"nodes", r.stats.node_count},          {"leaves", r.stats.leaf_count},
        {"max_depth", r.stats.max_depth},       {"avg_leaf_depth", r.stats.avg_leaf_depth},
        {"memory_bytes", r.stats.memory_bytes}, {"sah_cost", r.stats.sah_cost},
    };
    // A figure the structure does not have is null (Embree exposes no tree; a grid and the voxels
    // have no SAH): a 0 read as the lowest by a script that picks the best.
    if (r.stats.node_count == 0)
      for (const char* k : {"nodes", "leaves", "max_depth", "avg_leaf_depth"}) s["build"][k] = nullptr;
    if (!(r.stats.sah_cost > 0.0)) s["build"]["sah_cost"] = nullptr;
    for (const auto& [k, v] : r.stats.extra) s["build"][k] = v;
    // The constants the SAH cost is under: SAH costs compare only under the same ones.
    if (const auto c = sah_constants(r.name, so); c && r.stats.sah_cost > 0.0)
      s["build"]["sah_constants"] = {{"c_trav", c->first}, {"c_isect", c->second}};
    if (r.embree_bvh) {
      s["embree_binary_bvh"] = {
          {"sah_cost", r.embree_bvh->sah_cost},
          {"build_ms", r.embree_bvh->build_ms},
          {"nodes", r.embree_bvh->node_count},
          {"leaves", r.embree_bvh->leaf_count},
          {"max_depth", r.embree_bvh->max_depth},
          {"sah_ratio_ours_over_embree", ratio(r.stats.sah_cost, r.embree_bvh->sah_cost)},
      };
    }
    // Embree keeps no per-ray counters: its *_per_ray figures are null and marked so.
    s["per_ray_counters"] = !r.name.starts_with("embree");
    s["rays"] = nlohmann::json::object();
    for (const auto& [set, f] : r.queries)
      s["rays"][set] =
          query_json(f, s["per_ray_counters"].get<bool>(), metric_not_counted(HeatMetric::prims, r.name).empty());
    j["structures"].push_back(s);
  }
  if (embree) {
    j["ratios_vs_embree"] = nlohmann::json::object();
    for (const StructureResult& r : results) {
      if (&r == embree || !r.refused.empty()) continue;
      nlohmann::json rr = {{"build_ms", ratio(median(r.build_ms), median(embree->build_ms))},
                           {"memory_bytes", ratio(static_cast<double>(r.stats.memory_bytes),
                                                  static_cast<double>(embree->stats.memory_bytes))}};
      for (std::size_t k = 0; k < r.queries.size(); ++k) {
        const QueryFigures& a = r.queries[k].second;
        const QueryFigures* theirs = figures_on(*embree, r.queries[k].first);
        if (!theirs) continue;  // Embree refused a ray of this set
        const QueryFigures& b = *theirs;
        rr[r.queries[k].first] = {{"closest_mrays_1t", ratio(a.closest_1t, b.closest_1t)},
                                  {"closest_mrays_nt", ratio(a.closest_nt, b.closest_nt)},
                                  {"any_mrays_1t", ratio(a.any_1t, b.any_1t)},
                                  {"any_mrays_nt", ratio(a.any_nt, b.any_nt)}};
        if (a.packets && b.packets) {
          rr[r.queries[k].first]["closest_packet_mrays_1t"] = ratio(a.closest_packet_1t, b.closest_packet_1t);
          rr[r.queries[k].first]["any_packet_mrays_1t"] = ratio(a.any_packet_1t, b.any_packet_1t);
        }
      }
      j["ratios_vs_embree"][r.name] = rr;
    }
  }
  if (o.json) {
    j["machine"] = machine_json(all);
    write_stdout(json_text(j, 2) + '\n');
    return exit_code;
  }

  // ---- text ----
  // The columns: one thread, and the run's --threads (all hardware threads by
  // default). With one thread in all, the second pair is a second one-thread
  // measurement: "all=1T", so that no two headers read alike.
  const std::string nt = all > 1 ? std::to_string(all) + "T" : "all=1T";
  const std::string closest_nt = "closest " + nt, any_nt = "any " + nt;
  const std::string warm = o.warmup > 0 ? " after " + std::to_string(o.warmup) + " untimed" : "";
  const std::string embree_isa = so.embree.isa == EmbreeIsa::automatic
                                     ? std::string()
                                     : ", its " + std::string(embree_isa_name(so.embree.isa)) + " kernels";
  std::printf("scene %s: %s; %s; medians of %s%s; %s triangle test%s%s\n", o.scene.c_str(),
              count_of(scene.triangles.size(), "triangle").c_str(), count_of(all, "thread").c_str(),
              count_of(static_cast<std::size_t>(o.repeat), "run").c_str(), warm.c_str(), o.triangle_test.c_str(),
              kHaveEmbree ? (so.embree.robust ? "; Embree robust" : "; Embree default (not robust)") : "",
              kHaveEmbree ? embree_isa.c_str() : "");
  for (const RaySet& set : sets)
    std::printf("  %-8s %s%s\n", set.name.c_str(), count_of(set.rays.size(), "ray").c_str(),
                set.name == "shadow" && synthetic_light ? " (to a synthetic light: the scene has none)" : "");
  for (const StructureResult& r : results) {
    std::printf("\n%s\n", r.name.c_str());
    if (!r.refused.empty()) {
      std::printf("  not measured: %s\n", r.refused.c_str());
      continue;
    }
    const bool has_counters = !r.name.starts_with("embree");  // Embree exposes neither its tree nor per-ray counters
    std::printf("  build %.1f ms", median(r.build_ms));
    if (r.stats.node_count > 0)
      std::printf(", nodes %llu, leaves %llu, depth %u", static_cast<unsigned long long>(r.stats.node_count),
                  static_cast<unsigned long long>(r.stats.leaf_count), r.stats.max_depth);
    std::printf(", memory %s", format_bytes(r.stats.memory_bytes).c_str());
    if (r.stats.sah_cost > 0.0) {
      const std::string c = sah_constants_text(r.name, so);
      std::printf(", SAH %.3f%s", r.stats.sah_cost, c.empty() ? "" : (" (" + c + ")").c_str());
    }
    for (const auto& [k, v] : r.stats.extra) std::printf(", %s %.4g", k.c_str(), v);
    std::printf("\n");
    if (r.embree_bvh)
      std::printf("  Embree rtcBuildBVH binary tree: SAH %.3f (ours/embree %.3f), build %.1f ms, %llu leaves\n",
                  r.embree_bvh->sah_cost, ratio(r.stats.sah_cost, r.embree_bvh->sah_cost), r.embree_bvh->build_ms,
                  static_cast<unsigned long long>(r.embree_bvh->leaf_count));
    std::printf("  %-8s %15s %15s %15s %15s %10s %10s\n", "Mrays/s", "closest 1T", closest_nt.c_str(), "any 1T",
                any_nt.c_str(), "nodes/ray", "prims/ray");
    for (const auto& [set, f] : r.queries) {
      std::printf("  %-8s %15s %15s %15s %15s", set.c_str(), rate_text(f.closest_1t).c_str(),
                  rate_text(f.closest_nt).c_str(), rate_text(f.any_1t).c_str(), rate_text(f.any_nt).c_str());
      if (has_counters) {
        std::printf(" %10.1f %10.1f\n", f.closest_nodes, f.closest_prims);
      } else {
        std::printf(" %10s %10s\n", "n/a", "n/a");
      }
    }
    for (const auto& [set, why] : r.refused_sets) std::printf("  %-8s not measured: %s\n", set.c_str(), why.c_str());
    for (const auto& [set, f] : r.queries)
      if (f.packets)
        std::printf("  %-8s packets of 8, 1T: closest %.2f, any %.2f Mrays/s\n", set.c_str(), f.closest_packet_1t,
                    f.any_packet_1t);
  }
  if (embree) {
    std::printf("\nratios ours/embree (build and memory: lower is better; Mrays/s: higher is better)\n");
    for (const StructureResult& r : results) {
      if (&r == embree || !r.refused.empty()) continue;
      std::printf("  %s: build %.2f, memory %.2f\n", r.name.c_str(),
                  ratio(median(r.build_ms), median(embree->build_ms)),
                  ratio(static_cast<double>(r.stats.memory_bytes), static_cast<double>(embree->stats.memory_bytes)));
      for (std::size_t k = 0; k < r.queries.size(); ++k) {
        const QueryFigures& a = r.queries[k].second;
        const QueryFigures* theirs = figures_on(*embree, r.queries[k].first);
        if (!theirs) continue;  // Embree refused a ray of this set
        const QueryFigures& b = *theirs;
        std::printf("    %-8s closest 1T %.2f, %s %.2f, any 1T %.2f, %s %.2f\n", r.queries[k].first.c_str(),
                    ratio(a.closest_1t, b.closest_1t), closest_nt.c_str(), ratio(a.closest_nt, b.closest_nt),
                    ratio(a.any_1t, b.any_1t), any_nt.c_str(), ratio(a.any_nt, b.any_nt));
        if (a.packets && b.packets)
          std::printf("    %-8s packets of 8, 1T: closest %.2f, any %.2f\n", r.queries[k].first.c_str(),
                      ratio(a.closest_packet_1t, b.closest_packet_1t), ratio(a.any_packet_1t, b.any_packet_1t));
      }
    }
  }
  return exit_code;
}

}  // namespace

Command add_bench_command(CLI::App& parent, const GlobalOptions& global) {
  auto o = std::make_shared<BenchOptions>();
  CLI::App* sub = parent.add_subcommand(
      "bench",
      "Benchmark structures: build figures and closest/any-hit Mrays/s on primary, diffuse and shadow rays "
      "(medians of repeated runs), with ratios to Embree when it is among the structures");
  sub->add_option("SCENE", o->scene, "Scene file (.gltf, .glb, .obj) or builtin:NAME[?key=value&...]")->required();
  sub->add_option("--structure,-s", o->structures,
                  "Comma-separated structures of " + braced_names(bench_structure_names()) + " (default: bvh" +
                      (kHaveEmbree ? ",embree" : "") + ")" +
                      (kHaveEmbree ? "; embree-low, embree-medium, embree-high: Embree at that build quality "
                                     "(ratios are quoted against the plain embree row)"
                                   : ""))
      ->check(CLI::Validator([](std::string& text) { return name_list_problem(text, bench_structure_names()); },
                             "NAME[,NAME...]"));
  sub->add_option("--rays", o->rays, "Ray sets: primary, diffuse, shadow or all")
      ->check(CLI::IsMember({"primary", "diffuse", "shadow", "all"}))
      ->capture_default_str();
  sub->add_option("--size", o->size, "Primary rays: one per pixel of a WxH camera image")
      ->check(size_validator())
      ->capture_default_str();
  sub->add_option("--repeat,-n", o->repeat, "Runs per figure; the median is reported")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  sub->add_option("--warmup", o->warmup,
                  "Untimed rounds before the timed ones: builds of every structure and passes of every figure "
                  "(first runs in a process can be slower: cold caches, fresh memory)")
      ->check(CLI::Range(0, 100))
      ->capture_default_str();
  add_threads_option(sub, o->threads, "Threads of the all-threads figures and of builds (0: all hardware threads)");
  sub->add_flag("--json", o->json, "Print one JSON document instead of text");
  sub->add_option("--camera", o->camera,
                  "View: ex,ey,ez,tx,ty,tz[,fovdeg] or gltf:N; default: the scene's first camera, else a framing view");
  sub->add_option("--seed", o->seed, "Seed of the diffuse ray directions")->capture_default_str();
  add_triangle_test_option(sub, o->triangle_test);
  sub->add_flag("--no-epo", o->no_epo, "Skip the BVH's EPO figure (one extra pass per triangle)");
  o->structure_opts.add_to(sub);
  return {sub, [o, &global] { return run_bench(*o, global); }};
}

}  // namespace accelviz::cli
