#pragma once
// Parameter sweeps: what accuracy costs in time. For every setting of a
// cartesian product of structure options, build the structure R times and
// trace a fixed ray set R times (medians), plus one counting pass, and relate
// build time to trace time for a ray budget N:
//   total(N) = build_ms + N / rays_per_s.
// The Pareto front of (build time, trace time) shows which settings are ever
// worth using; the budget picks one of them.
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/accel/factory.h"
#include "core/analysis/calibrate.h"
#include "core/query/ray_sets.h"
#include "core/scene/scene.h"

namespace accelviz {

/// One swept parameter: "buckets=2,4,exact" → {"buckets", {"2", "4", "exact"}}.
struct SweepParam {
  std::string name;
  std::vector<std::string> values;
};

/// One point of the product: (parameter, value) pairs in the order given.
using SweepSetting = std::vector<std::pair<std::string, std::string>>;

/// "buckets=16 leaf=4" (space-separated pairs), for tables and chart labels.
std::string setting_label(const SweepSetting& setting);

/// Parameters a structure accepts (every structure also accepts "triangle").
const std::vector<std::string>& sweep_param_names(std::string_view structure);

/// The structures a sweep measures: bvh, kdtree, grid, octree, voxels (each
/// setting is built over the scene's triangles; not tlas, whose instances
/// those builds would flatten, nor brute force or Embree, which have no knobs).
const std::vector<std::string>& sweep_structures();

/// Parses "NAME=V1,V2,...". Throws std::invalid_argument on a missing '=' or an empty value.
SweepParam parse_sweep_param(std::string_view text);

/// The cartesian product of `params` (first parameter varies slowest), after
/// checking every name and value for `structure` on a copy of the options.
/// Throws std::invalid_argument naming the unknown parameter or bad value,
/// and for a parameter given twice or an empty list.
std::vector<SweepSetting> expand_sweep(std::string_view structure, std::span<const SweepParam> params);

/// The most settings one sweep takes (expand_sweep refuses more, before making any).
inline constexpr std::size_t kMaxSweepSettings = 10000;

/// Whether parameter `name` sets a query option only (the triangle test):
/// settings that differ only in such parameters build the same structure.
bool sweep_param_is_query(std::string_view name);

/// The first setting before settings[i] that builds the same structure
/// (equal but for query parameters), if any.
std::optional<std::size_t> earlier_same_build(std::span<const SweepSetting> settings, std::size_t i);

/// Writes one setting into the structure and query options. Throws
/// std::invalid_argument for an unknown name or a bad value (same messages).
void apply_sweep_setting(std::string_view structure, const SweepSetting& setting, StructureOptions& options,
                         QueryOptions& query);

// ---- shared-edge probes (triangle-test accuracy) ---------------------------------

/// A ray aimed at the midpoint of an edge that exactly two triangles share
/// (same vertex positions), from outside the scene along a seeded direction
/// from which the two triangles lie on opposite sides of the edge (so the
/// edge is crossed, not seen as a silhouette fold).
/// On a closed surface such a ray must hit one of the two triangles; a test
/// that misses both lets it leak through the mesh.
struct EdgeProbe {
  Ray ray;
  std::uint32_t tri_a = 0, tri_b = 0;
};

/// Up to `max_probes` probes over the shared edges (evenly sampled in edge
/// order; an edge without a crossing direction in 32 draws is skipped),
/// directions from `seed`. Deterministic.
std::vector<EdgeProbe> shared_edge_probes(std::span<const Triangle> triangles, std::size_t max_probes,
                                          std::uint64_t seed);

struct EdgeLeaks {
  std::uint64_t probes = 0;
  std::uint64_t misses = 0;       ///< rays that miss both triangles of the shared edge (a leak)
  std::uint64_t double_hits = 0;  ///< rays that hit both triangles
};

/// Tests every probe against its two triangles with `test`.
EdgeLeaks count_edge_leaks(std::span<const Triangle> triangles, std::span<const EdgeProbe> probes, TriangleTest test);

/// For every triangle, the triangles across its three edges (v0v1, v1v2,
/// v2v0) where exactly two triangles share that edge's positions; kInvalidId
/// elsewhere (boundary, non-manifold or degenerate).
std::vector<std::array<std::uint32_t, 3>> shared_edge_neighbours(std::span<const Triangle> triangles);

/// Of `rays` with closest hits `hits` (as traced with `test`), how many are
/// also hit by a neighbour of the hit triangle at the same distance (|dt| <=
/// 1e-5 max(1, t)): the ray went through the shared edge and both sides
/// reported it.
std::uint64_t count_ray_double_hits(std::span<const Triangle> triangles,
                                    std::span<const std::array<std::uint32_t, 3>> neighbours,
                                    std::span<const Ray> rays, std::span<const Hit> hits, TriangleTest test);

// ---- measuring ---------------------------------------------------------------------

struct SweepConfig {
  std::string structure = "bvh";
  StructureOptions base;      ///< options before each setting is applied
  QueryOptions query;         ///< before each setting is applied
  int repeat = 3;             ///< builds and timed passes per setting (medians)
  /// Untimed rounds per setting (a build and a trace pass each) before the
  /// timed ones: the first build and pass of a setting touch memory the next
  /// ones reuse.
  int warmup = 1;
  unsigned threads = 0;       ///< build and trace threads (0: all hardware threads)
  double ray_budget = 1e6;    ///< N of total(N)
  /// Asked during builds and between timed passes (any thread); false
  /// cancels the setting being measured (BuildCancelled). Empty: never.
  std::function<bool()> keep_going;
  /// Told the fraction of one setting's measurement done: inside each build
  /// (from the builder's threads, as builders report) and after each build
  /// and pass. Its return value is ignored (keep_going cancels). Empty: none.
  ProgressCallback progress;
};

struct SweepResult {
  SweepSetting setting;
  std::vector<double> build_ms_runs;
  double build_ms = 0;          ///< median of the builder's own figure
  std::uint64_t memory_bytes = 0;
  std::uint64_t nodes = 0, leaves = 0;
  std::uint32_t max_depth = 0;
  double sah_cost = 0;          ///< 0 where the structure reports none
  double epo = -1;              ///< < 0: not available (BVH only)
  std::vector<double> rays_per_s_runs;
  double rays_per_s = 0;        ///< median of the timed closest-hit passes, no counters
  double nodes_per_ray = 0;     ///< counting pass: mean nodes visited
  double prims_per_ray = 0;     ///< counting pass: mean triangle tests
  double hit_fraction = 0;
  EdgeLeaks edges;              ///< with the setting's triangle test (probes == 0 when not measured)
  /// Main ray set, when edges are measured: rays whose closest hit is also
  /// hit, at the same distance (relative 1e-5), by a triangle sharing an
  /// edge with it: the ray struck the shared edge and the test reported it
  /// on both sides (counted twice by any-hit or counting queries).
  std::uint64_t ray_double_hits = 0;
  std::string triangle_test;    ///< "watertight" or "fast"
  /// Set when the build figures (build_ms*, memory, nodes, leaves, depth,
  /// SAH, EPO) are those of an earlier setting that builds the same tree
  /// (earlier_same_build): its label. Empty when measured here.
  std::string build_of;

  /// Trace time of `rays` rays at the measured rate, in ms.
  double trace_ms(double rays) const { return rays_per_s > 0 ? rays / rays_per_s * 1e3 : 0.0; }
  /// build_ms + trace_ms(rays).
  double total_ms(double rays) const { return build_ms + trace_ms(rays); }
};

/// One structure timed the way `sweep` and `calibrate` time it:
/// `warmup` untimed rounds (a build and a trace pass each: the first build
/// and pass touch memory the next ones reuse), `repeat` timed builds (the
/// builder's own figure; the last tree kept), `repeat` timed closest-hit
/// passes over `rays` without counters, then a counting pass (outside the
/// timings). Never two trees in memory at once.
struct TimedStructure {
  std::unique_ptr<Accelerator> accel;   ///< the last tree built
  std::vector<double> build_ms_runs;    ///< one per timed build
  std::vector<double> rays_per_s_runs;  ///< one per timed pass (empty without rays)
  std::vector<Hit> hits;                ///< of the counting pass
  double nodes_per_ray = 0;             ///< counting pass: mean nodes visited
  double prims_per_ray = 0;             ///< counting pass: mean triangle tests
  double hit_fraction = 0;
};
/// `build(progress)` builds one tree, calling `progress` as builders do
/// (false cancels). `keep_going` (empty: never cancel) is asked between
/// builds and passes and during builds; false throws BuildCancelled.
/// `time_builds` false: no timed builds (build_ms_runs stays empty); the
/// tree of the last warm-up round is kept (one untimed build without one).
/// `report` (empty: none) is told the fraction of the whole done, never less
/// than it was told before: builds and passes are steps weighed by the mean
/// time of the builds and of the passes measured so far (the same weight
/// until both have been); inside builds, from the builder's threads.
TimedStructure time_structure(
    const std::function<std::unique_ptr<Accelerator>(const ProgressCallback& progress)>& build,
    std::span<const Ray> rays, const QueryOptions& query, unsigned threads, int warmup, int repeat,
    const std::function<bool()>& keep_going, bool time_builds = true, const ProgressCallback& report = {});

/// BVH built with the default constants (1, 1) and with the calibrated ones
/// (1, C_isect of the query's triangle test), judged by the same yardstick.
struct CalibratedTree {
  float c_trav = 1, c_isect = 1;  ///< the constants it was built with
  double build_ms = 0;            ///< median of `repeat` builds (the builder's own figure)
  double sah_own = 0;             ///< SAH cost under the constants it was built with
  double sah_calibrated = 0;      ///< SAH cost under the calibrated constants
  double rays_per_s = 0;
  double nodes_per_ray = 0, prims_per_ray = 0;
  std::uint64_t nodes = 0;
};
struct CalibrationReport {
  Calibration machine;
  double c_isect = 0;  ///< for the request's triangle test
  CalibratedTree with_default, with_calibrated;
};

/// Builds both trees over `triangles` and traces `rays`, each timed by
/// time_structure() (one untimed round, medians of `repeat` builds and
/// passes): `accelviz calibrate --scene` and the Cost of accuracy panel.
CalibrationReport compare_calibrated_bvh(std::span<const Triangle> triangles, std::span<const Ray> rays,
                                         const Calibration& c, const QueryOptions& query, unsigned threads, int repeat,
                                         const std::function<bool()>& keep_going = {});

/// Called before each setting with its index and the count; false cancels (BuildCancelled).
using SweepProgress = std::function<bool(std::size_t index, std::size_t count, const std::string& label)>;

/// Measures one setting over `rays` (and `probes` when non-empty).
/// `same_build`: the result of an earlier setting that builds the same tree
/// (earlier_same_build): its build figures are taken, not measured again
/// (a second measurement of one tree would report its noise as a cost).
SweepResult measure_sweep_setting(std::span<const Triangle> triangles, std::span<const Ray> rays,
                                  std::span<const EdgeProbe> probes, const SweepConfig& config,
                                  const SweepSetting& setting, const SweepResult* same_build = nullptr);

/// Every setting in order (settings that build the same tree share its build figures).
std::vector<SweepResult> run_sweep(std::span<const Triangle> triangles, std::span<const Ray> rays,
                                   std::span<const EdgeProbe> probes, const SweepConfig& config,
                                   std::span<const SweepSetting> settings, const SweepProgress& progress = {});

// ---- analysis ------------------------------------------------------------------------

/// A setting's costs, all to be minimised: x build ms, y trace ms, and z a
/// third cost (the shared-edge leaks, where they were measured; else 0).
struct ParetoPoint {
  double x = 0, y = 0, z = 0;
};

/// Indices of the points no other point dominates when minimising every
/// coordinate (q dominates p when q is nowhere larger and somewhere
/// smaller), sorted by x then y. Equal points are all kept. Non-finite
/// points are never on the front.
std::vector<std::size_t> pareto_front(std::span<const ParetoPoint> points);

/// The results as points: build ms, trace ms for `rays` rays, and the edge
/// leaks (probe misses) when the triangle test was swept, so that an
/// accurate setting stays on the front beside a faster one that leaks.
std::vector<ParetoPoint> sweep_points(std::span<const SweepResult> results, double rays);

/// Index of the result with the smallest total_ms(rays); results must not be empty.
std::size_t best_for_budget(std::span<const SweepResult> results, double rays);
/// The same among the results whose shared-edge probes found no leak; none
/// when no probe was made or every result leaks.
std::optional<std::size_t> best_without_leaks(std::span<const SweepResult> results, double rays);

/// How far one setting's timed runs lie apart, the largest over the settings:
/// (max - min) / min of its rays/s passes and of its builds (0 with fewer than
/// two runs). Time differences between settings below it are not a ranking;
/// the tree figures (SAH, nodes and tests per ray) do not scatter.
struct TimingScatter {
  double rays_per_s = 0.0, build_ms = 0.0;
};
TimingScatter timing_scatter(std::span<const SweepResult> results);

/// CSV with a header row: the swept parameters as columns, then the figures.
std::string sweep_csv(std::span<const SweepResult> results, double ray_budget);

}  // namespace accelviz

namespace accelviz {

/// The ray set a sweep traces, made as the benchmark makes it: primary rays
/// of `camera` (W×H); for diffuse and shadow, one closest-hit pass of a
/// default BVH finds the primary hits they start from (shadow rays aim at the
/// scene's lights, or at synthetic_light when it has none, reported in
/// `synthetic_light`).
std::vector<Ray> sweep_ray_set(const Scene& scene, const Camera& camera, int width, int height, RayKind kind,
                               std::uint64_t seed, unsigned threads, bool* synthetic_light = nullptr);

}  // namespace accelviz
