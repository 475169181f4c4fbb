// Sweep: parameter parsing and expansion, the Pareto front on hand-made
// points, shared-edge leak counting, and small end-to-end sweeps whose
// figures must be sane (no timing thresholds: only positivity and orderings
// that do not depend on the machine).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <thread>

#include "core/analysis/sweep.h"
#include "core/query/camera.h"
#include "core/scene/load.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace accelviz::unity_test_sweep {
namespace {

std::vector<Ray> small_primary(const Scene& scene, int w = 48, int h = 36) {
  const Camera cam = frame_bounds(scene.bounds(), static_cast<float>(w) / h);
  return primary_rays(cam, w, h);
}

TEST(SweepParams, ParsesNameAndValues) {
  const SweepParam p = parse_sweep_param("buckets=2,4,exact");
  EXPECT_EQ(p.name, "buckets");
  EXPECT_EQ(p.values, (std::vector<std::string>{"2", "4", "exact"}));
  EXPECT_THROW(parse_sweep_param("buckets"), std::invalid_argument);
  EXPECT_THROW(parse_sweep_param("buckets="), std::invalid_argument);
  EXPECT_THROW(parse_sweep_param("buckets=2,,4"), std::invalid_argument);
  EXPECT_THROW(parse_sweep_param("buckets=2,"), std::invalid_argument);
}

TEST(SweepParams, CartesianProductFirstParameterSlowest) {
  const std::vector<SweepParam> params{{"buckets", {"4", "exact"}}, {"leaf", {"1", "2", "8"}}};
  const std::vector<SweepSetting> s = expand_sweep("bvh", params);
  ASSERT_EQ(s.size(), 6u);
  EXPECT_EQ(setting_label(s[0]), "buckets=4 leaf=1");
  EXPECT_EQ(setting_label(s[2]), "buckets=4 leaf=8");
  EXPECT_EQ(setting_label(s[5]), "buckets=exact leaf=8");
}

TEST(SweepParams, UnknownNameOrBadValueIsNamed) {
  auto message = [](std::string_view structure, std::vector<SweepParam> params) {
    try {
      expand_sweep(structure, params);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message("bvh", {{"bukets", {"4"}}}).find("bukets"), std::string::npos);
  EXPECT_NE(message("bvh", {{"buckets", {"1"}}}).find("'1'"), std::string::npos);
  EXPECT_NE(message("bvh", {{"buckets", {"300"}}}).find("'300'"), std::string::npos);
  EXPECT_NE(message("bvh", {{"splitter", {"sah"}}}).find("'sah'"), std::string::npos);
  EXPECT_NE(message("bvh", {{"ctrav", {"-1"}}}).find("'-1'"), std::string::npos);
  EXPECT_NE(message("grid", {{"res", {"16x16"}}}).find("'16x16'"), std::string::npos);
  EXPECT_NE(message("grid", {{"depth", {"3"}}}).find("depth"), std::string::npos);
  EXPECT_NE(message("kdtree", {{"mailbox", {"yes"}}}).find("'yes'"), std::string::npos);
  EXPECT_NE(message("bvh", {{"triangle", {"exact"}}}).find("'exact'"), std::string::npos);
  EXPECT_NE(message("bvh", {{"leaf", {"1"}}, {"leaf", {"2"}}}).find("twice"), std::string::npos);
  // The SAH costs in the command line's range: 3e38 overflowed the float sums and built bigger leaves.
  EXPECT_NE(message("bvh", {{"cisect", {"1", "3e38"}}}).find("'3e38' (must be a number from 1e-06 to 1e+06)"),
            std::string::npos);
  EXPECT_NE(message("kdtree", {{"ctrav", {"1e-300"}}}).find("'1e-300'"), std::string::npos);
  // A fixed resolution leaves lambda nothing to choose.
  EXPECT_NE(message("grid", {{"lambda", {"1", "2"}}, {"res", {"4x4x4"}}}).find("lambda and res together"),
            std::string::npos);
  // Counted before they are made: 2e14 settings filled 8 GB before the first build.
  std::vector<std::string> many(200);
  for (std::size_t i = 0; i < many.size(); ++i) many[i] = std::to_string(1 + i);
  EXPECT_NE(message("bvh", {{"ctrav", many}, {"cisect", many}})
                .find("give 4e+04 settings (200 x 200 values), more "
                      "than the 10000 one sweep takes"),
            std::string::npos)
      << message("bvh", {{"ctrav", many}, {"cisect", many}});
  EXPECT_EQ(expand_sweep("bvh", std::vector<SweepParam>{{"ctrav", many}, {"cisect", {"1", "2"}}}).size(), 400u);
}

TEST(SweepParams, AppliesToTheRightOptions) {
  StructureOptions o;
  QueryOptions q;
  apply_sweep_setting("bvh", {{"buckets", "exact"}, {"leaf", "8"}, {"triangle", "fast"}}, o, q);
  EXPECT_EQ(o.bvh.splitter, BvhSplitter::exact_sah);
  EXPECT_EQ(o.bvh.max_leaf_size, 8);
  EXPECT_GE(o.bvh.leaf_size_cap, 8);
  EXPECT_EQ(q.triangle_test, TriangleTest::moller_trumbore);
  apply_sweep_setting("grid", {{"res", "4x5x6"}}, o, q);
  EXPECT_EQ(o.grid.resolution, (std::array<int, 3>{4, 5, 6}));
  apply_sweep_setting("kdtree", {{"mailbox", "off"}, {"depth", "12"}}, o, q);
  EXPECT_FALSE(o.kdtree.mailboxing);
  EXPECT_EQ(o.kdtree.max_depth, 12);
  apply_sweep_setting("voxels", {{"level", "5"}}, o, q);
  EXPECT_EQ(o.voxels.level, 5);
}

TEST(Pareto, HandMadePointSet) {
  // Front: (1,9) (2,5) (2,5) (4,3) (7,1). Dominated: (3,6) by (2,5); (5,3)
  // by (4,3) (same y, larger x); (8,8); (7,2) by (7,1). NaN never on the front.
  const std::vector<ParetoPoint> pts{{3, 6}, {1, 9}, {2, 5}, {5, 3}, {4, 3}, {8, 8}, {7, 1}, {7, 2}, {2, 5}, {NAN, 0}};
  const std::vector<std::size_t> front = pareto_front(pts);
  EXPECT_EQ(front, (std::vector<std::size_t>{1, 2, 8, 4, 6}));
  EXPECT_TRUE(pareto_front(std::vector<ParetoPoint>{}).empty());
  EXPECT_EQ(pareto_front(std::vector<ParetoPoint>{{1, 1}}), (std::vector<std::size_t>{0}));
}

// The third cost (edge leaks): a slower setting that does not leak stays on
// the front beside a faster one that does (the audit found sweep's front and
// "best" naming only triangle=fast, which leaked through 413 of 3,336 probes).
TEST(Pareto, LeaksKeepTheAccurateSettingOnTheFront) {
  SweepResult fast, watertight, slow_leaky;
  fast.setting = {{"triangle", "fast"}};
  fast.build_ms = 2;
  fast.rays_per_s = 2e6;
  fast.edges = {100, 7, 0};
  watertight.setting = {{"triangle", "watertight"}};
  watertight.build_ms = 2;
  watertight.rays_per_s = 1.5e6;
  watertight.edges = {100, 0, 0};
  slow_leaky = fast;  // slower than fast and leaks as much: dominated
  slow_leaky.rays_per_s = 1e6;
  std::vector<SweepResult> r{fast, watertight, slow_leaky};
  EXPECT_EQ(pareto_front(sweep_points(r, 1e6)), (std::vector<std::size_t>{0, 1}));
  // Without the leaks (not measured), watertight is dominated by fast.
  std::vector<SweepResult> unmeasured = r;
  for (SweepResult& x : unmeasured) x.edges = {};
  EXPECT_EQ(pareto_front(sweep_points(unmeasured, 1e6)), (std::vector<std::size_t>{0}));
  EXPECT_EQ(best_for_budget(r, 1e6), 0u);
  EXPECT_EQ(best_without_leaks(r, 1e6), std::optional<std::size_t>(1));
  EXPECT_EQ(best_without_leaks(unmeasured, 1e6), std::nullopt);  // no probe made: nothing to say
  r[1].edges.misses = 1;
  EXPECT_EQ(best_without_leaks(std::vector<SweepResult>{r[0], r[1]}, 1e6), std::nullopt);  // every one leaks
}

TEST(Pareto, BestForBudgetTradesBuildAgainstTrace) {
  SweepResult cheap_build, fast_trace;
  cheap_build.build_ms = 1;
  cheap_build.rays_per_s = 1e6;  // 1e6 rays: 1000 ms
  fast_trace.build_ms = 100;
  fast_trace.rays_per_s = 2e6;  // 1e6 rays: 500 ms
  const std::vector<SweepResult> r{cheap_build, fast_trace};
  EXPECT_EQ(best_for_budget(r, 1e4), 0u);  // 11 ms vs 105 ms
  EXPECT_EQ(best_for_budget(r, 1e6), 1u);  // 1001 ms vs 600 ms
  EXPECT_DOUBLE_EQ(r[1].total_ms(1e6), 600.0);
}

// The doubt behind these tests: the first probe generator (536a7c5) drew any
// direction, and on builtin:teapot?size=800 (300 probes, seed 1) the
// watertight test "missed" 11; every one of the 11 was a silhouette fold (seen
// along the ray, both triangles lie on the same side of the edge, so a ray
// through the edge grazes the surface and may rightly miss both). Probes now
// only cross their edge; these tests fail on that old generator.

// Side of the third vertices of a probe's two triangles, seen along its ray (double precision).
std::pair<double, double> sides(const std::vector<Triangle>& tris, const EdgeProbe& p) {
  const Triangle &A = tris[p.tri_a], &B = tris[p.tri_b];
  const glm::vec3 va[3] = {A.v0, A.v1, A.v2}, vb[3] = {B.v0, B.v1, B.v2};
  std::vector<glm::dvec3> shared;
  glm::dvec3 ca(0.0), cb(0.0);
  for (const glm::vec3& v : va) {
    if (std::find(std::begin(vb), std::end(vb), v) != std::end(vb))
      shared.push_back(glm::dvec3(v));
    else
      ca = glm::dvec3(v);
  }
  for (const glm::vec3& v : vb)
    if (std::find(std::begin(va), std::end(va), v) == std::end(va)) cb = glm::dvec3(v);
  EXPECT_EQ(shared.size(), 2u);
  if (shared.size() != 2) return {0.0, 0.0};
  const glm::dvec3 e = shared[1] - shared[0], d(p.ray.direction);
  return {glm::dot(glm::cross(e, ca - shared[0]), d), glm::dot(glm::cross(e, cb - shared[0]), d)};
}

TEST(EdgeProbes, EveryProbeCrossesItsEdgeNeverAFold) {
  // The doubted case itself: teapot?size=800, 300 probes, seed 1 (as tests/cli/sweep.sh runs it).
  const Scene scene = load_scene("builtin:teapot?size=800");
  const std::vector<EdgeProbe> probes = shared_edge_probes(scene.triangles, 300, 1);
  ASSERT_EQ(probes.size(), 300u);
  int folds = 0;
  for (const EdgeProbe& p : probes) {
    const auto [sa, sb] = sides(scene.triangles, p);
    folds += !(sa * sb < 0.0);
  }
  EXPECT_EQ(folds, 0);
  EXPECT_EQ(count_edge_leaks(scene.triangles, probes, TriangleTest::watertight).misses, 0u);
}

TEST(EdgeProbes, SharpFoldIsProbedOnlyFromCrossingDirections) {
  // Two triangles folded 10 degrees apart along the x axis (a sharp V):
  // from most directions both lie on the same side of the edge.
  const float a = 10.0f * 3.14159265f / 180.0f;
  const std::vector<Triangle> tris{{{0, 0, 0}, {1, 0, 0}, {0.5f, 1, 0}},
                                   {{1, 0, 0}, {0, 0, 0}, {0.5f, std::cos(a), std::sin(a)}}};
  std::size_t total = 0;
  for (std::uint64_t seed = 1; seed <= 50; ++seed) {
    const std::vector<EdgeProbe> probes = shared_edge_probes(tris, 1, seed);
    total += probes.size();
    for (const EdgeProbe& p : probes) {
      const auto [sa, sb] = sides(tris, p);
      EXPECT_LT(sa * sb, 0.0) << "seed " << seed;
      EXPECT_EQ(count_edge_leaks(tris, std::vector<EdgeProbe>{p}, TriangleTest::watertight).misses, 0u) << seed;
    }
  }
  EXPECT_GT(total, 10u);  // crossing directions exist (about 1 in 18 draws) and are found
}

// A closed, welded icosphere (subdivided icosahedron on the unit sphere):
// every edge is shared by exactly two triangles.
std::vector<Triangle> icosphere(int levels) {
  const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
  std::vector<glm::vec3> v{{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                           {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  for (glm::vec3& p : v) p = glm::normalize(p);
  std::vector<std::array<int, 3>> f{{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                                    {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                                    {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<int, int>, int> mid;
    auto m = [&](int i, int j) {
      const auto k = std::minmax(i, j);
      const auto it = mid.find(k);
      if (it != mid.end()) return it->second;
      v.push_back(glm::normalize(0.5f * (v[k.first] + v[k.second])));
      return mid[k] = static_cast<int>(v.size()) - 1;
    };
    std::vector<std::array<int, 3>> g;
    for (const auto& [a, b, c] : f) {
      const int ab = m(a, b), bc = m(b, c), ca = m(c, a);
      g.insert(g.end(), {{a, ab, ca}, {b, bc, ab}, {c, ca, bc}, {ab, bc, ca}});
    }
    f = std::move(g);
  }
  std::vector<Triangle> out;
  for (const auto& [a, b, c] : f) out.push_back({v[a], v[b], v[c]});
  return out;
}

TEST(EdgeProbes, WatertightNeverLeaksThroughAClosedMesh) {
  const std::vector<Triangle> tris = icosphere(4);  // 5,120 triangles, 7,680 edges
  const auto nb = shared_edge_neighbours(tris);
  for (const auto& n : nb)
    for (std::uint32_t o : n) ASSERT_NE(o, kInvalidId);  // closed: every edge has its neighbour
  const std::vector<EdgeProbe> probes = shared_edge_probes(tris, 4000, 3);
  ASSERT_GT(probes.size(), 3500u);
  const EdgeLeaks wt = count_edge_leaks(tris, probes, TriangleTest::watertight);
  const EdgeLeaks fast = count_edge_leaks(tris, probes, TriangleTest::moller_trumbore);
  EXPECT_EQ(wt.misses, 0u);
  EXPECT_LE(fast.misses + fast.double_hits, fast.probes);
  std::printf("icosphere edge probes: %zu; watertight misses 0, double hits %llu; fast misses %llu, double hits %llu\n",
              probes.size(), static_cast<unsigned long long>(wt.double_hits),
              static_cast<unsigned long long>(fast.misses), static_cast<unsigned long long>(fast.double_hits));
}

TEST(EdgeProbes, RayDoubleHitsCountRaysThroughASharedEdge) {
  // A unit square split along its diagonal; rays straight down (exact floats).
  const std::vector<Triangle> tris{{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}}, {{0, 0, 0}, {1, 1, 0}, {0, 1, 0}}};
  const auto nb = shared_edge_neighbours(tris);
  EXPECT_EQ(nb[0][2], 1u);  // edge v2v0 of the first is the diagonal
  EXPECT_EQ(nb[1][0], 0u);  // edge v0v1 of the second
  EXPECT_EQ(nb[0][0], kInvalidId);
  const std::vector<Ray> rays{Ray({0.5f, 0.5f, 1}, {0, 0, -1}),    // on the diagonal
                              Ray({0.75f, 0.25f, 1}, {0, 0, -1}),  // inside the first only
                              Ray({2, 2, 1}, {0, 0, -1})};         // misses
  std::vector<Hit> hits(rays.size());
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const WatertightRay wr(rays[i].direction);
    for (std::uint32_t t = 0; t < tris.size(); ++t) {
      Hit h;
      if (intersect_triangle(TriangleTest::watertight, rays[i], wr, tris[t], rays[i].tmin, rays[i].tmax, h) &&
          (!hits[i].valid() || h.t < hits[i].t)) {
        h.prim = t;  // the test fills t, u, v only
        hits[i] = h;
      }
    }
  }
  ASSERT_TRUE(hits[0].valid());
  ASSERT_TRUE(hits[1].valid());
  EXPECT_EQ(count_ray_double_hits(tris, nb, rays, hits, TriangleTest::watertight), 1u);
}

TEST(EdgeProbes, WatertightNeverLeaksThroughTheTeapotsSharedEdges) {
  const Scene scene = load_scene("builtin:teapot?size=3000");
  const std::vector<EdgeProbe> probes = shared_edge_probes(scene.triangles, 5000, 7);
  ASSERT_GT(probes.size(), 1000u);
  const EdgeLeaks wt = count_edge_leaks(scene.triangles, probes, TriangleTest::watertight);
  const EdgeLeaks fast = count_edge_leaks(scene.triangles, probes, TriangleTest::moller_trumbore);
  EXPECT_EQ(wt.probes, probes.size());
  EXPECT_EQ(wt.misses, 0u);
  // The fast test may leak; record, do not require. Its counts stay within the probes.
  EXPECT_LE(fast.misses + fast.double_hits, fast.probes);
  std::printf("teapot edge probes: %zu; fast misses %llu, double hits %llu; watertight double hits %llu\n",
              probes.size(), static_cast<unsigned long long>(fast.misses),
              static_cast<unsigned long long>(fast.double_hits), static_cast<unsigned long long>(wt.double_hits));
}

TEST(EdgeProbes, DeterministicAndOnlySharedEdges) {
  // Two triangles sharing one edge, plus a lone triangle: exactly one shared edge.
  const std::vector<Triangle> tris{
      {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{1, 0, 0}, {1, 1, 0}, {0, 1, 0}}, {{5, 5, 5}, {6, 5, 5}, {5, 6, 5}}};
  const std::vector<EdgeProbe> a = shared_edge_probes(tris, 10, 3), b = shared_edge_probes(tris, 10, 3);
  ASSERT_EQ(a.size(), 1u);
  EXPECT_EQ(a[0].tri_a, 0u);
  EXPECT_EQ(a[0].tri_b, 1u);
  EXPECT_EQ(a[0].ray.origin, b[0].ray.origin);
  EXPECT_EQ(a[0].ray.direction, b[0].ray.direction);
  EXPECT_EQ(count_edge_leaks(tris, a, TriangleTest::watertight).misses, 0u);
}

class SweepSah : public ::testing::TestWithParam<const char*> {};

TEST_P(SweepSah, EveryRequestedSettingHasSaneFiguresAndSahImprovesWithEffort) {
  const Scene scene = load_scene(GetParam());
  const std::vector<Ray> rays = small_primary(scene);
  const std::vector<SweepParam> params{{"splitter", {"median", "binned", "exact"}},
                                       {"triangle", {"watertight", "fast"}}};
  const std::vector<SweepSetting> settings = expand_sweep("bvh", params);
  SweepConfig cfg;
  cfg.repeat = 1;
  cfg.threads = 2;
  const std::vector<EdgeProbe> probes = shared_edge_probes(scene.triangles, 500, 1);
  const std::vector<SweepResult> res = run_sweep(scene.triangles, rays, probes, cfg, settings);
  ASSERT_EQ(res.size(), 6u);
  for (std::size_t i = 0; i < res.size(); ++i) {
    SCOPED_TRACE(setting_label(res[i].setting));
    EXPECT_EQ(res[i].setting, settings[i]);
    EXPECT_GT(res[i].build_ms, 0.0);
    EXPECT_GT(res[i].rays_per_s, 0.0);
    EXPECT_GT(res[i].memory_bytes, 0u);
    EXPECT_GT(res[i].sah_cost, 0.0);
    EXPECT_GE(res[i].epo, 0.0);
    EXPECT_GE(res[i].nodes_per_ray, 1.0);
    EXPECT_GT(res[i].total_ms(1e6), res[i].build_ms);
  }
  // Default binned B = 16. SAH cost (a property of the tree, not the clock):
  // median >= binned >= exact.
  EXPECT_GE(res[0].sah_cost, res[2].sah_cost);
  EXPECT_GE(res[2].sah_cost, res[4].sah_cost);
  // The same tree traced with either test visits the same nodes on rays that do not graze edges.
  EXPECT_NEAR(res[2].nodes_per_ray, res[3].nodes_per_ray, 0.05 * res[2].nodes_per_ray);
  EXPECT_EQ(res[2].edges.probes, probes.size());
  std::printf("%s SAH: median %.3f, binned %.3f, exact %.3f\n", GetParam(), res[0].sah_cost, res[2].sah_cost,
              res[4].sah_cost);
}

INSTANTIATE_TEST_SUITE_P(SmallScenes, SweepSah,
                         ::testing::Values("builtin:soup?size=3000", "builtin:teapot?size=3000"));

// Warm-up rounds run (more work is asked about) but never enter the figures.
TEST(Sweep, WarmupRoundsRunUntimed) {
  const Scene scene = load_scene("builtin:teapot?size=800");
  const std::vector<Ray> rays = small_primary(scene, 24, 18);
  const std::vector<SweepParam> params{{"buckets", {"8"}}};
  const std::vector<SweepSetting> settings = expand_sweep("bvh", params);
  std::size_t asked = 0;
  SweepConfig cfg;
  cfg.repeat = 3;
  cfg.threads = 1;
  cfg.keep_going = [&asked] {
    ++asked;
    return true;
  };
  std::size_t asked_by[3] = {};
  for (int warmup : {0, 2}) {
    cfg.warmup = warmup;
    asked = 0;
    const std::vector<SweepResult> res = run_sweep(scene.triangles, rays, {}, cfg, settings);
    ASSERT_EQ(res.size(), 1u);
    EXPECT_EQ(res[0].build_ms_runs.size(), 3u) << "warm-up " << warmup;
    EXPECT_EQ(res[0].rays_per_s_runs.size(), 3u) << "warm-up " << warmup;
    asked_by[warmup] = asked;
  }
  // Two more builds and two more passes, each asked about at least once.
  EXPECT_GE(asked_by[2], asked_by[0] + 4);
  EXPECT_EQ(SweepConfig{}.warmup, 1);
}

// A sweep's octree builds showed nothing until the setting ended: the setting's
// fraction now moves inside each build (1 % steps of the builder) and after
// each build and pass, and ends at 1.
TEST(Sweep, ASettingReportsItsProgressInsideItsBuilds) {
  const Scene scene = load_scene("builtin:teapot?size=3000");
  const std::vector<Ray> rays = small_primary(scene, 24, 18);
  const std::vector<SweepParam> params{{"depth", {"8"}}};
  const std::vector<SweepSetting> settings = expand_sweep("octree", params);
  SweepConfig cfg;
  cfg.structure = "octree";
  cfg.repeat = 2;
  cfg.warmup = 1;
  cfg.threads = 1;  // one builder thread: the fractions arrive in order
  std::vector<double> seen;
  cfg.progress = [&seen](double f) {
    seen.push_back(f);
    return true;
  };
  (void)measure_sweep_setting(scene.triangles, rays, {}, cfg, settings[0]);
  // Steps: 1 warm-up build + 2 timed builds, 1 warm-up pass + 2 timed passes + the counting pass.
  ASSERT_FALSE(seen.empty());
  EXPECT_DOUBLE_EQ(seen.back(), 1.0);
  std::set<double> inside;
  for (std::size_t i = 0; i < seen.size(); ++i) {
    EXPECT_GE(seen[i], 0.0);
    EXPECT_LE(seen[i], 1.0);
    if (i) {
      EXPECT_GE(seen[i], seen[i - 1]) << i;
    }
    if (seen[i] > 0.0 && seen[i] < 1.0) inside.insert(seen[i]);
  }
  // 7 steps end at 6 fractions below 1; the rest come from inside the builds.
  EXPECT_GE(inside.size(), 6u + 3u * 10u) << "each of the 3 builds reports at least 10 fractions inside";
}

// Steps weigh what they take: slow builds and quick passes (the audit's -n 100 read 24-39 % after
// its first quick build, the builds being half the steps but not of the time). Each build here
// sleeps 80 ms and a pass traces 16 rays (microseconds): after the warm-up round and two of the
// three timed builds, about 3 of 4 builds' time is done, where counting steps said 4 of 9.
TEST(Sweep, ProgressWeighsStepsByTheirTime) {
  const Scene scene = load_scene("builtin:soup?size=50");
  const std::vector<Ray> rays = small_primary(scene, 4, 4);
  std::vector<double> seen;
  double before_last_build = -1;
  int builds = 0;
  const auto build = [&](const ProgressCallback& progress) {
    if (builds++ == 3 && !seen.empty()) before_last_build = seen.back();
    std::this_thread::sleep_for(std::chrono::milliseconds(80));
    return build_accelerator("bvh", scene.triangles, StructureOptions{}, progress);
  };
  const TimedStructure t = time_structure(build, rays, QueryOptions{}, 1, /*warmup=*/1, /*repeat=*/3, {},
                                          /*time_builds=*/true, [&](double f) {
                                            if (!seen.empty()) {
                                              EXPECT_GE(f, seen.back());
                                            }
                                            seen.push_back(f);
                                            return true;
                                          });
  ASSERT_EQ(builds, 4);
  ASSERT_EQ(t.build_ms_runs.size(), 3u);
  ASSERT_FALSE(seen.empty());
  EXPECT_DOUBLE_EQ(seen.back(), 1.0);
  // Where the last build starts: 4 steps of 9 by count; 3 builds of 4 by time.
  EXPECT_GT(before_last_build, 0.6) << "counting steps would say 4/9 = 0.44";
  EXPECT_LT(before_last_build, 0.8);
}

TEST(SweepParams, SettingsDifferingOnlyInTheTriangleTestShareABuild) {
  const std::vector<SweepParam> params{{"triangle", {"watertight", "fast"}}, {"buckets", {"4", "8"}}};
  const std::vector<SweepSetting> s = expand_sweep("bvh", params);  // wt/4, wt/8, fast/4, fast/8
  ASSERT_EQ(s.size(), 4u);
  EXPECT_EQ(earlier_same_build(s, 0), std::nullopt);
  EXPECT_EQ(earlier_same_build(s, 1), std::nullopt);
  EXPECT_EQ(earlier_same_build(s, 2), std::optional<std::size_t>(0));
  EXPECT_EQ(earlier_same_build(s, 3), std::optional<std::size_t>(1));
  EXPECT_TRUE(sweep_param_is_query("triangle"));
  EXPECT_FALSE(sweep_param_is_query("buckets"));
}

// The audit: sweeping `triangle` rebuilt the same grid and reported 6.25 ms
// against 2.26 ms for it. Now the second setting takes the first's build
// figures, and is not built again for timing.
TEST(Sweep, TheSameTreeIsBuiltAndTimedOnce) {
  const Scene scene = load_scene("builtin:teapot?size=800");
  const std::vector<Ray> rays = small_primary(scene, 24, 18);
  const std::vector<SweepParam> params{{"lambda", {"1", "4"}}, {"triangle", {"watertight", "fast"}}};
  const std::vector<SweepSetting> settings = expand_sweep("grid", params);
  SweepConfig cfg;
  cfg.structure = "grid";
  cfg.repeat = 3;
  cfg.warmup = 1;
  cfg.threads = 1;
  const std::vector<SweepResult> res = run_sweep(scene.triangles, rays, {}, cfg, settings);
  ASSERT_EQ(res.size(), 4u);
  for (std::size_t i : {1u, 3u}) {
    SCOPED_TRACE(i);
    EXPECT_EQ(res[i].build_of, setting_label(res[i - 1].setting));
    EXPECT_EQ(res[i].build_ms_runs, res[i - 1].build_ms_runs);
    EXPECT_EQ(res[i].build_ms, res[i - 1].build_ms);
    EXPECT_EQ(res[i].memory_bytes, res[i - 1].memory_bytes);
    EXPECT_EQ(res[i].triangle_test, "fast");
    EXPECT_GT(res[i].rays_per_s, 0.0);  // traced with its own test
  }
  EXPECT_TRUE(res[0].build_of.empty());
  EXPECT_NE(res[0].memory_bytes, res[2].memory_bytes);  // lambda 1 and 4: two trees
  // A shared build costs no timed builds: warm-up's tree is traced.
  std::size_t asked_shared = 0, asked_own = 0;
  for (bool shared : {false, true}) {
    std::size_t& asked = shared ? asked_shared : asked_own;
    cfg.keep_going = [&asked] {
      ++asked;
      return true;
    };
    (void)measure_sweep_setting(scene.triangles, rays, {}, cfg, settings[1], shared ? &res[0] : nullptr);
  }
  EXPECT_LE(asked_shared + 3, asked_own) << "three timed builds left out";
}

TEST(Sweep, OtherStructuresSweepTheirOwnParameters) {
  const Scene scene = load_scene("builtin:soup?size=2000");
  const std::vector<Ray> rays = small_primary(scene, 24, 18);
  SweepConfig cfg;
  cfg.repeat = 1;
  cfg.threads = 1;
  for (const auto& [structure, param] :
       std::vector<std::pair<std::string, SweepParam>>{{"kdtree", {"mailbox", {"on", "off"}}},
                                                       {"grid", {"res", {"4x4x4", "16x16x16"}}},
                                                       {"octree", {"depth", {"2", "6"}}},
                                                       {"voxels", {"level", {"3", "5"}}}}) {
    SCOPED_TRACE(structure);
    cfg.structure = structure;
    const std::vector<SweepParam> params{param};
    const std::vector<SweepResult> res = run_sweep(scene.triangles, rays, {}, cfg, expand_sweep(structure, params));
    ASSERT_EQ(res.size(), 2u);
    for (const SweepResult& r : res) {
      EXPECT_GT(r.rays_per_s, 0.0);
      EXPECT_GE(r.build_ms, 0.0);
    }
    if (structure == "grid") {
      EXPECT_LT(res[0].memory_bytes, res[1].memory_bytes);
    }
  }
}

TEST(Sweep, CsvHasAHeaderAndOneRowPerSetting) {
  SweepResult r;
  r.setting = {{"buckets", "4"}, {"leaf", "2"}};
  r.build_ms = 2;
  r.rays_per_s = 1e6;
  r.triangle_test = "watertight";
  const std::vector<SweepResult> rs{r, r};
  const std::string csv = sweep_csv(rs, 1e6);
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 3);
  EXPECT_EQ(csv.rfind("buckets,leaf,label,", 0), 0u);
  EXPECT_NE(csv.find("\"buckets=4 leaf=2\""), std::string::npos);
}

TEST(Sweep, TimingScatterIsTheWidestSpreadOfOneSettingsOwnRuns) {
  std::vector<SweepResult> r(3);
  r[0].rays_per_s_runs = {100, 110, 105};  // 10 %
  r[0].build_ms_runs = {2.0, 3.0};         // 50 %
  r[1].rays_per_s_runs = {50, 75};         // 50 %
  r[2].rays_per_s_runs = {7};              // one run: no spread
  const TimingScatter t = timing_scatter(r);
  EXPECT_DOUBLE_EQ(t.rays_per_s, 0.5);
  EXPECT_DOUBLE_EQ(t.build_ms, 0.5);
  EXPECT_DOUBLE_EQ(timing_scatter(std::vector<SweepResult>(2)).rays_per_s, 0.0);
}

}  // namespace
}  // namespace accelviz::unity_test_sweep
