// accelviz flatten SCENE --instances IDS: the "flatten" what-if of a
// two-level scene (core/accel/tlas/flatten_what_if.h): the listed instances
// merged into one BLAS, against the two-level structure as it is; SAH cost,
// memory, build ms and the measured nodes, triangle tests and instances per
// primary ray of the same view for both.
#include <cstdio>
#include <memory>

#include "app/cli_common.h"
#include "core/accel/tlas/flatten_json.h"
#include "core/accel/tlas/flatten_what_if.h"
#include "core/accel/tlas/instance_ids.h"
#include "core/util/one_line.h"

namespace accelviz::cli {

namespace {

struct FlattenOptions {
  std::string scene;
  std::string instances;
  std::string size = "160x120";
  std::string camera;
  unsigned threads = 0;
  bool json = false;
};

int run_flatten(const FlattenOptions& o, const GlobalOptions& global) {
  const ImageSize size = parse_size(o.size);
  try {
    check_instance_ids(o.instances);  // before the scene loads
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("--") + e.what());
  }
  Progress progress(global.quiet);
  progress.begin("loading " + o.scene);
  const Scene scene = load_scene_noting_warnings(o.scene, global.quiet);
  progress.end(count_of(scene.instances.size(), "instance"));
  std::vector<std::uint32_t> ids;
  try {
    ids = parse_instance_ids(o.instances, scene.instances.size());
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("--") + e.what());
  }
  TlasOptions to;
  to.blas.threads = o.threads;
  to.blas.compute_epo = false;
  to.tlas = to.blas;
  const Camera cam = camera_for(o.camera, scene, size);
  progress.begin("building and tracing both");
  FlattenWhatIf w;
  try {
    w = flatten_what_if(scene, ids, cam, size.width, size.height, to);
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("--instances: ") + e.what());
  }
  progress.end("done");
  if (o.json) {
    nlohmann::json j = {{"scene", o.scene}};
    j.update(flatten_what_if_json(w));
    j["program"] = program_json();
    print_json_line(j);
    return 0;
  }
  std::printf("%s: %s merged into one BLAS (%s), %dx%d primary rays\n", o.scene.c_str(),
              count_of(w.merged_instances, "instance").c_str(), count_of(w.merged_triangles, "triangle").c_str(),
              size.width, size.height);
  std::printf("%-10s %9s %7s %10s %10s %9s %11s %11s %11s\n", "", "instances", "blas", "sah_cost", "memory_MiB",
              "build_ms", "nodes/ray", "prims/ray", "inst/ray");
  for (const auto& [name, f] : {std::pair<const char*, const TwoLevelFigures&>{"two-level", w.two_level},
                                std::pair<const char*, const TwoLevelFigures&>{"flattened", w.flattened}})
    std::printf("%-10s %9llu %7llu %10.3f %10.2f %9.1f %11.2f %11.2f %11.2f\n", name,
                static_cast<unsigned long long>(f.instances), static_cast<unsigned long long>(f.blas), f.sah_cost,
                static_cast<double>(f.memory_bytes) / 1048576.0, f.build_ms, f.mean_nodes, f.mean_prims,
                f.mean_instances);
  return 0;
}

Command add_flatten_command(CLI::App& parent, const GlobalOptions& global) {
  auto o = std::make_shared<FlattenOptions>();
  CLI::App* sub = parent.add_subcommand(
      "flatten", "What-if: merge the listed instances into one BLAS and compare SAH, memory and measured cost per ray");
  sub->add_option("SCENE", o->scene, "Scene file (.gltf, .glb, .obj) or builtin:NAME[?key=value&...]")->required();
  sub->add_option("--instances", o->instances,
                  "Instance ids to merge: ids and inclusive ranges, e.g. 0,2,5-9, or 'all'")
      ->required();
  sub->add_option("--size", o->size, "Primary rays traced, WxH")->check(size_validator())->capture_default_str();
  sub->add_option("--camera", o->camera, "Camera spec (default: the scene's default view)");
  add_threads_option(sub, o->threads, "Build threads (0: all)");
  sub->add_flag("--json", o->json, "One JSON object instead of the table");
  return {sub, [o, &global] { return run_flatten(*o, global); }};
}

const CommandRegistration register_flatten{add_flatten_command};

}  // namespace

}  // namespace accelviz::cli
