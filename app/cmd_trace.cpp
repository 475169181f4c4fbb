// accelviz trace SCENE --rays IN.rays --out OUT [--any]: traces a ray file
// through one structure and writes the closest hits (HITS) or the occlusion
// bits (OCCL); prints the build and trace figures as one JSON line.
#include <memory>

#include "app/cli_common.h"
#include "core/query/batch.h"
#include "core/query/ray_file.h"
#include "core/util/parallel.h"

namespace accelviz::cli {

namespace {

struct TraceOptions {
  std::string scene;
  std::string rays;
  std::string out;
  bool any = false;
  std::string structure = "bvh";
  unsigned threads = 0;
  std::string triangle_test = "watertight";
  bool force = false;
  StructureCli structure_opts;
};

int run_trace(const TraceOptions& o, const GlobalOptions& global) {
  check_output_path(o.out, o.force);
  o.structure_opts.say_unused({o.structure}, false, global.quiet);
  Progress progress(global.quiet);

  progress.begin("reading " + o.rays);
  const std::vector<Ray> rays = read_rays(o.rays);
  progress.end(count_of(rays.size(), "ray"));

  const Scene scene = load_scene_with_progress(o.scene, global.quiet, progress);
  const std::unique_ptr<Accelerator> accel =
      build_with_progress(o.structure, scene, o.structure_opts.to_options(o.threads, /*compute_epo=*/false), progress);
  const double build_ms = accel->build_stats().build_ms;
  // A ray the structure cannot take (Embree's limits) is named with its file
  // and index before any tracing.
  for (std::size_t i = 0; i < rays.size(); ++i)
    if (const std::string problem = accel->ray_problem(rays[i]); !problem.empty())
      throw std::runtime_error(o.rays + ": ray " + std::to_string(i) + ": " + o.structure + " " + problem);

  QueryOptions q;
  q.triangle_test = parse_triangle_test(o.triangle_test);
  // The timed pass runs without progress or counters: it measures tracing only.
  progress.begin(std::string("tracing (") + (o.any ? "any hit" : "closest hit") + ")");
  std::uint64_t hit_count = 0;
  double trace_ms = 0.0;
  if (o.any) {
    std::vector<std::uint8_t> occluded(rays.size());
    const auto t0 = Clock::now();
    trace_any(*accel, rays, occluded, q, o.threads);
    trace_ms = ms_since(t0);
    for (std::uint8_t b : occluded) hit_count += b;
    write_occlusion(o.out, occluded, o.force);
  } else {
    std::vector<Hit> hits(rays.size());
    const auto t0 = Clock::now();
    trace_closest(*accel, rays, hits, q, o.threads);
    trace_ms = ms_since(t0);
    for (const Hit& h : hits) hit_count += h.valid();
    write_hits(o.out, std::span<const Hit>(hits), o.force);
  }
  progress.end(std::to_string(static_cast<long long>(trace_ms)) + " ms");

  nlohmann::json j = {
      {"scene", o.scene},
      {"structure", o.structure},
      {"mode", o.any ? "any" : "closest"},
      {"rays", rays.size()},
      {"hits", hit_count},
      {"threads", resolve_threads(o.threads)},
      {"build_ms", build_ms},
      {"trace_ms", trace_ms},
      {"mrays_per_s", trace_ms > 0.0 ? static_cast<double>(rays.size()) / (trace_ms * 1e3) : 0.0},
      {"out", absolute_path(o.out)},
      {"program", program_json()},
  };
  print_json_line(j);
  return 0;
}

}  // namespace

Command add_trace_command(CLI::App& parent, const GlobalOptions& global) {
  auto o = std::make_shared<TraceOptions>();
  CLI::App* sub = parent.add_subcommand(
      "trace",
      "Trace a ray file (RAYS) through a structure; write closest hits (HITS) or, with --any, occlusion "
      "bits (OCCL). Formats: docs/file-formats-rays.md");
  sub->add_option("SCENE", o->scene, "Scene file (.gltf, .glb, .obj) or builtin:NAME[?key=value&...]")->required();
  sub->add_option("--rays,-r", o->rays, "Input ray file (RAYS)")->required();
  sub->add_option("--out,-o", o->out, "Output file: HITS, or OCCL with --any (never overwritten without --force)")
      ->required();
  sub->add_flag("--any", o->any, "Any-hit (occlusion) queries instead of closest hit");
  sub->add_option("--structure,-s", o->structure, "Acceleration structure")
      ->check(CLI::IsMember(structure_names()))
      ->capture_default_str();
  add_threads_option(sub, o->threads, "Threads for building and tracing (0: all hardware threads)");
  add_triangle_test_option(sub, o->triangle_test);
  sub->add_flag("--force,-f", o->force, "Overwrite an existing output file");
  o->structure_opts.add_to(sub);
  return {sub, [o, &global] { return run_trace(*o, global); }};
}

}  // namespace accelviz::cli
