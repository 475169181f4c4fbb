// Google Benchmark suite: build and traversal of our BVH beside Embree's, on
// the same triangles and the same rays (issue 11). Not a test: CI only
// builds it. Run it by hand (Release build):
//
//   build/perf/bench/accelviz_gbench --benchmark_filter=Trace
//   ACCELVIZ_BENCH_SCENE=../shared/assets/bunny.glb build/perf/bench/accelviz_gbench
//
// ACCELVIZ_BENCH_SCENE: any scene spec (file or builtin:...); default
// builtin:teapot?size=100000. Rays: 256x256 primary rays through the
// scene's framing camera, their diffuse bounces and shadow rays to a
// synthetic light (core/query/ray_sets.h), generated once from our BVH's
// hits, and `miss`: as many rays that start outside a sphere around the
// scene's bounds and point away from it (every structure rejects them at
// its root: their rate is the fixed cost of one query, the call, the ray's
// set-up and the root test). items_per_second is rays/s; compare our row
// with Embree's on the same ray set, as a ratio (docs/performance.md).
// TraceClosestPackets8 and TraceAnyPackets8: the same rays in packets of
// eight (Embree: rtcIntersect8, rtcOccluded8).
//
// HeatmapJob/POOL/W/H (built with the GUI's GL-free library): one job of
// the GUI's CPU heatmap (trace_progressive: levels of spacing 8, 4, 2, 1)
// on our BVH, two threads, nodes metric, the last level held as the GUI
// holds the one it shows; POOL 1: the levels' frames from a HeatmapFramePool
// (what the worker does), 0: new frames. Counter setup_ms: the job's time
// outside its tracing (the levels' set-up).
//
// Refit: Bvh::refit of our BVH over the scene's triangles (what a deforming
// mesh's BLAS gets per frame, docs/dynamics.md), alternating between the
// triangles as loaded and a copy whose every vertex moved by up to 1 % of
// the bounds' diagonal; counter build_ms: one fresh one-thread build of the
// same tree, to set the refit beside.
//
// InstanceOverlap/F: instance_overlap() (core/accel/tlas/tlas_overlap.h) of
// builtin:dynamic's 6,252 instances after SceneAnimator::step at frames
// 0..F (dt 0.04 s): what `animate` and the Dynamics panel measure per frame
// outside the frame's timings (docs/dynamics.md). Counter tlas_rebuild_ms:
// that frame's TLAS rebuild, to set the overlap's time beside; pairs and
// area_ratio: the overlap measured.
//
// ACCELVIZ_BENCH_PAIRING: which of our triangle tests meets which Embree
// mode (the pairs of `accelviz bench`): unset or `default`, our watertight
// test against Embree's default mode; `robust`, watertight against Embree's
// robust mode (`bench --embree-robust`); `fast`, Moller-Trumbore against
// Embree's default mode (`bench --triangle-test fast`).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "core/accel/bvh/bvh.h"
#include "core/accel/embree_backend.h"
#include "core/accel/factory.h"
#include "core/accel/tlas/tlas.h"
#include "core/accel/tlas/tlas_overlap.h"
#include "core/query/batch.h"
#include "core/query/camera.h"
#include "core/query/ray_sets.h"
#include "core/scene/animation.h"
#include "core/scene/effects.h"
#include "core/scene/load.h"
#include "core/util/timing.h"
#ifdef ACCELVIZ_GBENCH_HEATMAP
#include "ui/app/heatmap_worker.h"
#endif

namespace {

using namespace accelviz;

struct Fixture {
  Scene scene;
  std::vector<Ray> rays[4];  // primary, diffuse, shadow, miss

  Fixture() {
    const char* env = std::getenv("ACCELVIZ_BENCH_SCENE");
    scene = load_scene(env && *env ? env : "builtin:teapot?size=100000");
    const int w = 256, h = 256;
    const Camera cam = frame_bounds(scene.bounds(), 1.0f);
    rays[0] = primary_rays(cam, w, h);
    BvhOptions o;
    o.compute_epo = false;
    const Bvh bvh(scene.triangles, o);
    std::vector<Hit> hits(rays[0].size());
    trace_closest(bvh, rays[0], hits, QueryOptions{}, 0u);
    rays[1] = diffuse_rays(scene.triangles, rays[0], hits, 1);
    const Light light = synthetic_light(scene.bounds());
    rays[2] = shadow_rays(scene.triangles, rays[0], hits, std::span<const Light>(&light, 1));
    // Radially outward in the primary rays' directions from 1.5 diagonals
    // off the centre, beyond the bounds' circumsphere (half a diagonal):
    // they never enter the bounds.
    const Aabb b = scene.bounds();
    const glm::vec3 center = (b.lo + b.hi) * 0.5f;
    const float diagonal = glm::length(b.hi - b.lo);
    rays[3].reserve(rays[0].size());
    for (const Ray& r : rays[0]) rays[3].emplace_back(center + (1.5f * diagonal) * r.direction, r.direction);
  }
};

const Fixture& fixture() {
  static const Fixture f;
  return f;
}

/// ACCELVIZ_BENCH_PAIRING, read once.
struct Pairing {
  bool embree_robust = false;
  TriangleTest ours = TriangleTest::watertight;
};

const Pairing& pairing() {
  static const Pairing p = [] {
    const char* env = std::getenv("ACCELVIZ_BENCH_PAIRING");
    Pairing r;
    if (env == nullptr || *env == '\0' || std::strcmp(env, "default") == 0) return r;
    if (std::strcmp(env, "robust") == 0) {
      r.embree_robust = true;
    } else if (std::strcmp(env, "fast") == 0) {
      r.ours = TriangleTest::moller_trumbore;
    } else {
      throw std::invalid_argument(std::string("ACCELVIZ_BENCH_PAIRING: expected default, robust or fast, got '") + env +
                                  "'");
    }
    return r;
  }();
  return p;
}

const char* kSetNames[4] = {"primary", "diffuse", "shadow", "miss"};

std::unique_ptr<Accelerator> make(const std::string& name, unsigned threads) {
  StructureOptions so;
  so.threads = threads;
  so.bvh.compute_epo = false;
  so.embree.robust = pairing().embree_robust;
  if (name == "lbvh") {
    so.bvh.splitter = BvhSplitter::lbvh;
    return build_accelerator("bvh", fixture().scene.triangles, so);
  }
  return build_accelerator(name, fixture().scene.triangles, so);
}

/// Build time; range(0) = threads.
void build(benchmark::State& state, const std::string& name) {
  const auto threads = static_cast<unsigned>(state.range(0));
  const std::size_t n = fixture().scene.triangles.size();
  // Our BVH's build phases (mean ms per build): the binary tree, the wide tree
  // collapsed from it, the triangle blocks.
  double phase[3] = {0.0, 0.0, 0.0};
  const char* kPhases[3] = {"build_topology_ms", "build_wide_ms", "build_blocks_ms"};
  for (auto _ : state) {
    auto accel = make(name, threads);
    benchmark::DoNotOptimize(accel.get());
    const BuildStats& bs = accel->build_stats();
    for (int p = 0; p < 3; ++p)
      if (const auto it = bs.extra.find(kPhases[p]); it != bs.extra.end()) phase[p] += it->second;
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * n));  // triangles/s
  if (phase[0] > 0.0)
    for (int p = 0; p < 3; ++p)
      state.counters[std::string(kPhases[p]).substr(6)] = phase[p] / static_cast<double>(state.iterations());
}

/// Single-thread closest hit (any = false) or any hit; range(0) = ray set
/// (0 primary, 1 diffuse, 2 shadow, 3 miss);
/// packets: in packets of eight consecutive rays (trace_*_packets).
void trace(benchmark::State& state, const std::string& name, bool any, bool packets) {
  const std::vector<Ray>& rays = fixture().rays[state.range(0)];
  state.SetLabel(kSetNames[state.range(0)]);
  const auto accel = make(name, 0);
  std::vector<Hit> hits(rays.size());
  std::vector<std::uint8_t> occluded(rays.size());
  QueryOptions q;
  q.triangle_test = pairing().ours;
  for (auto _ : state) {
    if (packets && any)
      trace_any_packets(*accel, rays, occluded, q, BatchOptions{1u});
    else if (packets)
      trace_closest_packets(*accel, rays, hits, q, BatchOptions{1u});
    else if (any)
      trace_any(*accel, rays, occluded, q, 1u);
    else
      trace_closest(*accel, rays, hits, q, 1u);
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * rays.size()));  // rays/s
}

#ifdef ACCELVIZ_GBENCH_HEATMAP
/// One job of the GUI's CPU heatmap; range(0) = pool (0 or 1), range(1) x
/// range(2) = image size.
void heatmap_job(benchmark::State& state) {
  static const auto built = [] {
    auto b = std::make_shared<BuiltStructure>();
    b->accel = make("bvh", 0);
    return std::shared_ptr<const BuiltStructure>(b);
  }();
  HeatmapRequest r;
  r.structure = built;
  r.options.width = static_cast<int>(state.range(1));
  r.options.height = static_cast<int>(state.range(2));
  r.options.threads = 2;
  r.camera = frame_bounds(fixture().scene.bounds(), static_cast<float>(r.options.width) / r.options.height);
  HeatmapFramePool pool;
  std::shared_ptr<const HeatmapFrame> shown;
  std::uint64_t id = 0;
  // One job; returns its time outside the tracing.
  const auto job = [&] {
    const auto t0 = std::chrono::steady_clock::now();
    double trace_ms = 0.0;
    trace_progressive(
        r, ++id, [] { return true; },
        [&](std::shared_ptr<const HeatmapFrame> f) {
          trace_ms = f->summary.render_ms;
          shown = std::move(f);
        },
        state.range(0) != 0 ? &pool : nullptr);
    return ms_since(t0) - trace_ms;
  };
  job();  // untimed: the pool's first frames (the GUI's first job at a size)
  double setup_ms = 0.0;
  for (auto _ : state) setup_ms += job();
  state.counters["setup_ms"] = setup_ms / static_cast<double>(state.iterations());
}
#endif

void refit(benchmark::State& state) {
  const std::vector<Triangle>& rest = fixture().scene.triangles;
  std::vector<Triangle> moved = rest;
  const Aabb b = fixture().scene.bounds();
  const float step = 0.01f * glm::length(b.hi - b.lo);
  for (Triangle& t : moved)
    for (glm::vec3* v : {&t.v0, &t.v1, &t.v2}) {
      // A shared vertex moves alike in every triangle: the offset hashes its position.
      const std::uint32_t h = std::bit_cast<std::uint32_t>(v->x) * 73856093u ^
                              std::bit_cast<std::uint32_t>(v->y) * 19349663u ^
                              std::bit_cast<std::uint32_t>(v->z) * 83492791u;
      *v += step * glm::vec3(static_cast<float>(h & 1023u) / 1023.0f - 0.5f,
                             static_cast<float>((h >> 10) & 1023u) / 1023.0f - 0.5f,
                             static_cast<float>((h >> 20) & 1023u) / 1023.0f - 0.5f);
    }
  BvhOptions o;
  o.compute_epo = false;
  o.threads = 1;
  const auto t0 = std::chrono::steady_clock::now();
  Bvh bvh(rest, o);
  const double build_ms = ms_since(t0);
  bool at_rest = true;
  for (auto _ : state) {
    at_rest = !at_rest;
    bvh.refit(at_rest ? rest : moved);
  }
  state.counters["build_ms"] = build_ms;
  state.counters["triangles"] = static_cast<double>(rest.size());
}

/// range(0) = the last frame stepped (frames 0..F at 0.04 s).
void instance_overlap_bench(benchmark::State& state) {
  static const Scene scene = make_builtin("builtin:dynamic");
  Tlas tlas(scene);
  SceneAnimator animator(scene, tlas);
  FrameStats frame;
  for (std::int64_t f = 0; f <= state.range(0); ++f) frame = animator.step(static_cast<float>(f) * 0.04f);
  InstanceOverlap o;
  for (auto _ : state) {
    o = instance_overlap(tlas);
    benchmark::DoNotOptimize(o);
  }
  state.counters["tlas_rebuild_ms"] = frame.tlas_rebuild_ms;
  state.counters["pairs"] = static_cast<double>(o.overlapping_pairs);
  state.counters["area_ratio"] = o.area_ratio;
  state.counters["instances"] = static_cast<double>(o.instances);
}

void register_all() {
  std::vector<std::string> names = {"bvh", "lbvh"};
  if (kHaveEmbree) names.push_back("embree");
  for (const std::string& n : names) {
    // Threads 1, 2, 4, ... up to the machine's hardware threads, and that
    // count itself (on 2 cores: 1 and 2; on 16: 1, 2, 4, 8, 16).
    benchmark::internal::Benchmark* b = benchmark::RegisterBenchmark(("Build/" + n).c_str(), build, n);
    const unsigned hw = std::max(2u, std::thread::hardware_concurrency());
    for (unsigned t = 1; t < hw; t *= 2) b->Arg(t);
    b->Arg(hw)->Unit(benchmark::kMillisecond)->UseRealTime();
    for (bool packets : {false, true}) {
      if (packets && n == "lbvh") continue;  // the same packet walk as bvh over another tree
      const std::string suffix = packets ? "Packets8/" : "/";
      benchmark::RegisterBenchmark(("TraceClosest" + suffix + n).c_str(), trace, n, false, packets)
          ->DenseRange(0, 3)
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime();  // the batch may trace on a worker thread: wall time, not this thread's CPU time
      benchmark::RegisterBenchmark(("TraceAny" + suffix + n).c_str(), trace, n, true, packets)
          ->DenseRange(0, 3)
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime();
    }
  }
  benchmark::RegisterBenchmark("Refit", refit)->Unit(benchmark::kMillisecond)->UseRealTime();
  benchmark::RegisterBenchmark("InstanceOverlap", instance_overlap_bench)
      ->DenseRange(0, 5)
      ->Unit(benchmark::kMillisecond)
      ->UseRealTime();
#ifdef ACCELVIZ_GBENCH_HEATMAP
  benchmark::RegisterBenchmark("HeatmapJob", heatmap_job)
      ->ArgsProduct({{0, 1}, {1280}, {720}})
      ->Args({0, 1920, 1080})
      ->Args({1, 1920, 1080})
      ->Unit(benchmark::kMillisecond)
      ->UseRealTime();
#endif
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  try {
    pairing();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "accelviz_gbench: %s\n", e.what());
    return 1;
  }
  register_all();
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
