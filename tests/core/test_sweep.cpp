// Sweep: parameter parsing and expansion, the Pareto front on hand-made
// points, shared-edge leak counting, and small end-to-end sweeps whose
// figures must be sane (no timing thresholds: only positivity and orderings
// that do not depend on the machine).
#include "core/analysis/sweep.h"

#include "core/query/camera.h"
#include "core/scene/load.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace accelviz {
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
  const std::vector<Point2> pts{{3, 6}, {1, 9}, {2, 5}, {5, 3}, {4, 3}, {8, 8},
                                {7, 1}, {7, 2}, {2, 5}, {NAN, 0}};
  const std::vector<std::size_t> front = pareto_front(pts);
  EXPECT_EQ(front, (std::vector<std::size_t>{1, 2, 8, 4, 6}));
  EXPECT_TRUE(pareto_front(std::vector<Point2>{}).empty());
  EXPECT_EQ(pareto_front(std::vector<Point2>{{1, 1}}), (std::vector<std::size_t>{0}));
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

TEST(EdgeProbes, WatertightNeverLeaksOnTheClosedTeapot) {
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
  const std::vector<Triangle> tris{{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}},
                                   {{1, 0, 0}, {1, 1, 0}, {0, 1, 0}},
                                   {{5, 5, 5}, {6, 5, 5}, {5, 6, 5}}};
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
  const std::vector<SweepParam> params{{"splitter", {"median", "binned", "exact"}}, {"triangle", {"watertight", "fast"}}};
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

TEST(Sweep, OtherStructuresSweepTheirOwnParameters) {
  const Scene scene = load_scene("builtin:soup?size=2000");
  const std::vector<Ray> rays = small_primary(scene, 24, 18);
  SweepConfig cfg;
  cfg.repeat = 1;
  cfg.threads = 1;
  for (const auto& [structure, param] : std::vector<std::pair<std::string, SweepParam>>{
           {"kdtree", {"mailbox", {"on", "off"}}},
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

}  // namespace
}  // namespace accelviz
