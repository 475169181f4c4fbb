// accelviz verify SCENE --rays N --structure all|LIST [--seed S] [--threads T] [--json]:
// traces random, adversarial and camera rays on every structure (closest and
// any hit) and compares with the double-precision reference. Prints one
// summary line (after a line per structure that refused the scene or rays);
// exit 1 when any disagreement is not explained by rounding, or when a
// structure named by itself (not through "all") refused.
#include "app/cli_common.h"

#include "core/analysis/verify.h"
#include "core/util/parallel.h"

#include <iostream>
#include <memory>

namespace accelviz::cli {

namespace {

struct VerifyOptions {
  std::string scene;
  std::size_t rays = 100000;
  std::string structure = "all";
  std::uint64_t seed = 1;
  unsigned threads = 0;
  bool json = false;
};

int run_verify(const VerifyOptions& o, const GlobalOptions& global) {
  std::vector<VerifyStructure> structures;
  try {
    structures = parse_verify_structures(o.structure, o.threads);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  Progress progress(global.quiet);
  progress.begin("loading " + o.scene);
  const Scene scene = load_scene_noting_warnings(o.scene, global.quiet);
  progress.end(count_of(scene.triangles.size(), "triangle"));
  if (scene.triangles.empty() && !scene.instances.empty())
    throw std::runtime_error(o.scene +
                             ": instanced and too large to flatten; verify needs the flattened triangles for its "
                             "brute-force reference");

  progress.begin("verifying " + count_of(structures.size(), "structure"));
  std::vector<Ray> rays;
  try {
    rays = verify_rays(scene.triangles, o.rays, o.seed);
  } catch (const std::range_error& e) {  // bounds near the float range: no camera rays can be made
    throw std::runtime_error(o.scene + ": " + e.what());
  }
  // "tlas": two levels from the scene's instances, checked against the flattened brute force.
  const VerifyResult r = verify_structures(scene.triangles, rays, structures, o.threads, &scene, progress.callback());
  progress.end(std::to_string(static_cast<long long>(r.total_ms)) + " ms");

  if (!global.quiet)
    for (const std::string& ex : r.examples) std::cerr << "verify: " << ex << "\n";

  const VerifyCounts& t = r.total;
  // A refusal is no disagreement: with "all" the structure is reported as not
  // (wholly) checked and the verdict is the others'; a structure named by
  // itself that refuses makes the run fail (exit 1), as its refusal does in
  // render, bench and trace.
  const bool ok = r.ok() && !r.named_refused();
  if (o.json) {
    nlohmann::json per = nlohmann::json::object();
    for (const auto& [label, c] : r.per_structure)
      per[label] = {{"rays", c.rays},
                    {"mismatched_prim", c.mismatched_prim},
                    {"t_beyond_tolerance", c.t_beyond_tolerance},
                    {"anyhit_disagree", c.anyhit_disagree},
                    {"near_ties", c.near_ties},
                    {"build_ms", c.build_ms},
                    {"ok", c.ok()}};
    nlohmann::json not_checked = nlohmann::json::object();
    for (const VerifyNotChecked& n : r.not_checked) {
      not_checked[n.label] = {{"rays", n.rays}, {"scene_refused", n.scene_refused}, {"reason", n.reason}};
      if (!n.scene_refused) not_checked[n.label]["first_ray"] = n.first_ray;
    }
    print_json_line({{"scene", o.scene},
                     {"triangles", scene.triangles.size()},
                     {"rays", r.rays},
                     {"seed", o.seed},
                     {"threads", resolve_threads(o.threads)},
                     {"reference_hits", r.reference_hits},
                     {"structures", per},
                     {"not_checked", not_checked},
                     {"mismatched_prim", t.mismatched_prim},
                     {"t_beyond_tolerance", t.t_beyond_tolerance},
                     {"anyhit_disagree", t.anyhit_disagree},
                     {"near_ties", t.near_ties},
                     {"reference_ms", r.reference_ms},
                     {"total_ms", r.total_ms},
                     {"ok", ok}});
  } else {
    for (const VerifyNotChecked& n : r.not_checked) {
      if (n.scene_refused)
        std::cout << n.label << ": not checked: " << n.reason << "\n";
      else
        std::cout << n.label << ": " << n.rays << " of " << r.rays << " rays not checked (the first, ray "
                  << n.first_ray << ": " << n.reason << ")\n";
    }
    std::cout << "verify: " << o.scene << " rays=" << r.rays << " structures=" << r.per_structure.size()
              << " mismatched_prim=" << t.mismatched_prim << " t_beyond_tolerance=" << t.t_beyond_tolerance
              << " anyhit_disagree=" << t.anyhit_disagree << " near_ties=" << t.near_ties << " -> "
              << (ok ? "OK" : "FAIL") << '\n';
  }
  return ok ? 0 : 1;
}

Command add_verify_command(CLI::App& parent, const GlobalOptions& global) {
  auto o = std::make_shared<VerifyOptions>();
  CLI::App* sub = parent.add_subcommand(
      "verify", "Compare every structure with a double-precision brute-force reference on random, adversarial "
                "and camera rays (closest and any hit); exit 1 on a disagreement rounding does not explain. "
                "See docs/robustness.md");
  sub->add_option("SCENE", o->scene, "Scene file (.gltf, .glb, .obj) or builtin:NAME[?key=value&...]")->required();
  sub->add_option("--rays,-n", o->rays, "Number of rays")->check(CLI::Range(std::size_t{1}, std::size_t{1} << 32))->capture_default_str();
  sub->add_option("--structure,-s", o->structure,
                  "all, or a comma list of brute, brute-bbox, bvh (every splitter: binned, exact, median, lbvh), "
                  "bvh-binned, bvh-exact, bvh-median, bvh-lbvh, kdtree, "
                  "grid, octree, tlas (two-level over the scene's instances; not in all), embree")
      ->capture_default_str();
  sub->add_option("--seed", o->seed, "Seed of the ray generator")->capture_default_str();
  add_threads_option(sub, o->threads, "Threads (0: all hardware threads)");
  sub->add_flag("--json", o->json, "One JSON line with per-structure counts instead of the summary line");
  return {sub, [o, &global] { return run_verify(*o, global); }};
}

const CommandRegistration register_verify{add_verify_command};

}  // namespace

}  // namespace accelviz::cli
