// accelviz robustness SCENE [--structure S] [--rays N] [--seed S] [--threads T] [--json]:
// the robustness lab (core/analysis/robustness_lab.h) on the command line.
// Adversarial rays (through vertices, shared edges, axis-aligned with ±0,
// grazing) traced with Moller-Trumbore vs watertight triangle tests and plain
// vs padded slab tests (and a structure's own traversal with both triangle
// tests); per variant the misses, double hits and wrong hits against the
// double-precision reference, and the time each costs. Exit 0 after a run:
// the figures are the result (the fast variants are expected to fail); 1 when
// the structure named refused the scene or some rays (Embree's limits), after
// the figures of what ran.
#include <cstdio>
#include <iostream>
#include <memory>

#include "app/cli_common.h"
#include "core/analysis/robustness_lab.h"
#include "core/util/parallel.h"

namespace accelviz::cli {

nlohmann::json lab_result_json(const LabResult& r) {
  nlohmann::json variants = nlohmann::json::array();
  for (const LabVariant& v : r.variants) {
    nlohmann::json miss_f = nlohmann::json::object(), dbl_f = nlohmann::json::object();
    for (int f = 0; f < kLabFamilies; ++f) {
      miss_f[to_string(static_cast<LabFamily>(f))] = v.misses_by_family[f];
      dbl_f[to_string(static_cast<LabFamily>(f))] =
          v.double_hits_counted ? nlohmann::json(v.double_hits_by_family[f]) : nlohmann::json(nullptr);
    }
    // Embree's rows: its own modes, not our triangle test; it reports one hit per ray (no double hits).
    const nlohmann::json test = !v.embree_mode.empty()                        ? "embree-" + v.embree_mode
                                : v.triangle_test == TriangleTest::watertight ? "watertight"
                                                                              : "moller-trumbore";
    variants.push_back(
        {{"name", v.name},
         {"triangle_test", test},
         {"embree_mode", v.embree_mode.empty() ? nlohmann::json(nullptr) : nlohmann::json(v.embree_mode)},
         {"slab", v.own_structure ? "structure" : (v.padded_slab ? "padded" : "plain")},
         {"misses", v.misses},
         {"not_traced", v.not_traced},
         {"double_hits", v.double_hits_counted ? nlohmann::json(v.double_hits) : nlohmann::json(nullptr)},
         {"wrong", v.wrong},
         {"misses_by_family", miss_f},
         {"double_hits_by_family", dbl_f},
         {"ms", v.ms},
         {"mrays_per_s", v.mrays_per_s}});
  }
  nlohmann::json fam = nlohmann::json::object();
  for (int f = 0; f < kLabFamilies; ++f) fam[to_string(static_cast<LabFamily>(f))] = r.rays_by_family[f];
  return {{"triangles", r.triangles},       {"rays", r.rays},
          {"rays_by_family", fam},          {"reference_hits", r.reference_hits},
          {"reference_ms", r.reference_ms}, {"variants", variants}};
}

namespace {

struct RobustnessOptions {
  std::string scene;
  std::size_t rays = 20000;
  std::string structure;
  std::uint64_t seed = 1;
  unsigned threads = 0;
  bool json = false;
};

int run_robustness(const RobustnessOptions& o, const GlobalOptions& global) {
  if (!o.structure.empty()) {
    if (o.structure == "voxels")
      throw UsageError("--structure voxels: voxel hits are voxels, not triangles; the lab compares triangle hits");
    bool known = false;
    for (const std::string& n : structure_names()) known = known || n == o.structure;
    if (!known)
      throw UsageError("--structure: unknown '" + o.structure + "' (valid: " + structure_names_joined() + ")");
  }
  Progress progress(global.quiet);
  progress.begin("loading " + o.scene);
  const Scene scene = load_scene_noting_warnings(o.scene, global.quiet);
  progress.end(count_of(scene.triangles.size(), "triangle"));
  if (scene.triangles.empty()) throw UsageError(o.scene + ": no triangles to aim adversarial rays at");

  LabOptions lo;
  lo.rays = o.rays;
  lo.seed = o.seed;
  lo.structure = o.structure;
  lo.threads = o.threads;
  progress.begin("robustness lab, " + count_of(o.rays, "ray"));
  LabResult r;
  try {
    r = run_robustness_lab(scene.triangles, lo);
  } catch (const std::invalid_argument& e) {
    throw UsageError(std::string("--structure ") + o.structure + ": " + e.what());
  }
  progress.end(std::to_string(static_cast<long long>(r.reference_ms)) + " ms reference");
  // The structure named refused the scene or rays (Embree's limits): the lab's
  // own variants are reported, the structure's on the rays it took, and the
  // run exits 1, as a refusal does in verify and bench.
  const bool refused = !r.structure_refused.empty() || r.structure_rays_refused > 0;
  std::string refusal;
  if (!r.structure_refused.empty()) {
    refusal = o.structure + ": not checked: " + without_name_prefix(r.structure_refused, o.structure);
  } else if (r.structure_rays_refused > 0) {
    refusal = o.structure + ": " + std::to_string(r.structure_rays_refused) + " of " + std::to_string(r.rays) +
              " rays not traced (the first, ray " + std::to_string(r.structure_first_refused_ray) + ": " +
              r.structure_refused_ray_reason + ")";
  }

  if (o.json) {
    nlohmann::json j = {{"scene", o.scene}, {"seed", o.seed}};
    j.update(lab_result_json(r));
    j["not_checked"] = refused ? nlohmann::json(refusal) : nlohmann::json(nullptr);
    j["program"] = program_json();
    print_json_line(j);
    return refused ? 1 : 0;
  }
  std::cout << "robustness: " << o.scene << " triangles=" << r.triangles << " rays=" << r.rays << " (vertex "
            << r.rays_by_family[0] << ", edge " << r.rays_by_family[1] << ", axis " << r.rays_by_family[2]
            << ", grazing " << r.rays_by_family[3] << ") reference_hits=" << r.reference_hits << "\n";
  char line[256];
  std::snprintf(line, sizeof line, "%-36s %8s %12s %8s %10s %9s\n", "variant", "misses", "double_hits", "wrong", "ms",
                "Mrays/s");
  std::cout << line;
  for (const LabVariant& v : r.variants) {
    if (v.not_traced == r.rays && r.rays > 0) {  // a structure that took none of the rays: nothing to count
      std::snprintf(line, sizeof line, "%-36s %8s %12s %8s %10s %9s\n", v.name.c_str(), "-", "-", "-", "-", "-");
      std::cout << line;
      continue;
    }
    const std::string doubles = v.double_hits_counted ? std::to_string(v.double_hits) : "n/a";
    std::snprintf(line, sizeof line, "%-36s %8llu %12s %8llu %10.1f %9.2f\n", v.name.c_str(),
                  static_cast<unsigned long long>(v.misses), doubles.c_str(), static_cast<unsigned long long>(v.wrong),
                  v.ms, v.mrays_per_s);
    std::cout << line;
  }
  if (refused) std::cout << refusal << "\n";
  std::cout.flush();
  return refused ? 1 : 0;
}

Command add_robustness_command(CLI::App& parent, const GlobalOptions& global) {
  auto o = std::make_shared<RobustnessOptions>();
  CLI::App* sub = parent.add_subcommand(
      "robustness",
      "Robustness lab: adversarial rays (vertices, shared edges, axis-aligned with +0/-0, grazing) traced with "
      "Moller-Trumbore vs watertight triangle tests and plain vs padded slab tests; misses, double hits and wrong "
      "hits against the double-precision reference, and the time of each. See docs/robustness.md");
  sub->add_option("SCENE", o->scene, "Scene file (.gltf, .glb, .obj) or builtin:NAME[?key=value&...]")->required();
  sub->add_option("--rays,-n", o->rays, "Number of rays (split evenly over the four families)")
      ->check(CLI::Range(std::size_t{4}, std::size_t{1} << 28))
      ->capture_default_str();
  sub->add_option("--structure,-s", o->structure,
                  "Also trace with this structure's own traversal, both triangle tests (not voxels); embree: its "
                  "default and its robust mode (it ignores our triangle test)");
  sub->add_option("--seed", o->seed, "Seed of the ray generator")->capture_default_str();
  add_threads_option(sub, o->threads, "Threads for the builds and the reference (0: all)");
  sub->add_flag("--json", o->json, "One JSON line instead of the table");
  return {sub, [o, &global] { return run_robustness(*o, global); }};
}

const CommandRegistration register_robustness{add_robustness_command};

}  // namespace

}  // namespace accelviz::cli
