// The Cost of accuracy panel's engine (ui/app/sweep_worker.h): parameter
// text, applying a clicked point to the structure choice, chart series, the
// synchronous sweep with live snapshots and cancel, the worker's supersession,
// and the default-vs-calibrated BVH comparison.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <thread>

#include "core/accel/factory.h"
#include "core/query/camera.h"
#include "core/query/ray_sets.h"
#include "core/scene/load.h"
#include "ui/app/sweep_worker.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace accelviz::unity_test_app_sweep_worker {
namespace {

std::shared_ptr<const LoadedScene> scene_of(const std::string& spec) {
  auto s = std::make_shared<LoadedScene>();
  s->spec = spec;
  s->scene = load_scene(spec);
  return s;
}

SweepRequest small_request(const std::string& spec, const std::string& params) {
  SweepRequest r;
  r.scene = scene_of(spec);
  r.structure = "bvh";
  r.params = parse_sweep_params_text("bvh", params);
  r.camera = frame_bounds(r.scene->scene.bounds(), 1.5f);
  r.width = 24;
  r.height = 16;
  r.threads = 1;
  r.edge_probes = 200;
  return r;
}

// Polls `done` for up to 60 s (the worker runs on its own thread).
template <class F>
bool eventually(F done) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < end) {
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return false;
}

TEST(SweepParamsText, ParsesPairsAndNamesWhatIsWrong) {
  const std::vector<SweepParam> p = parse_sweep_params_text("bvh", "buckets=2,8,exact  leaf=1,4;triangle=fast");
  ASSERT_EQ(p.size(), 3u);
  EXPECT_EQ(p[0].name, "buckets");
  EXPECT_EQ(p[0].values, (std::vector<std::string>{"2", "8", "exact"}));
  EXPECT_EQ(p[1].values, (std::vector<std::string>{"1", "4"}));
  EXPECT_EQ(p[2].name, "triangle");
  try {
    parse_sweep_params_text("grid", "buckets=2");
    FAIL() << "buckets is not a grid parameter";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("buckets"), std::string::npos) << e.what();
  }
  EXPECT_THROW(parse_sweep_params_text("bvh", "  "), std::invalid_argument);
  EXPECT_THROW(parse_sweep_params_text("bvh", "leaf=1 leaf=2"), std::invalid_argument);
  EXPECT_THROW(parse_sweep_params_text("bvh", "buckets=1"), std::invalid_argument);  // below 2
}

// The structures `accelviz sweep` takes have a default that parses; the others are refused, as the
// command refuses them (a tlas swept in the window measured one instance over the flattened mesh).
TEST(SweepParamsText, EverySweptStructureHasAValidDefaultAndTheOthersAreRefused) {
  const std::vector<std::string>& swept = sweep_structures();
  for (const std::string& name : structure_names()) {
    SCOPED_TRACE(name);
    const std::string text = default_sweep_params_text(name);
    EXPECT_FALSE(text.empty());
    if (std::find(swept.begin(), swept.end(), name) != swept.end()) {
      EXPECT_NO_THROW(parse_sweep_params_text(name, text));
    } else {
      try {
        parse_sweep_params_text(name, text);
        ADD_FAILURE() << name << " was accepted";
      } catch (const std::invalid_argument& e) {
        EXPECT_EQ(std::string(e.what()), name + " is not swept (the sweep measures bvh, kdtree, grid, octree, voxels)");
      }
    }
  }
  EXPECT_EQ(swept.size(), 5u);
}

TEST(ApplySweepPoint, WritesTheSettingIntoTheChoiceOrLeavesItAlone) {
  StructureChoice c;
  c.name = "grid";
  EXPECT_EQ(apply_sweep_point(c, "bvh", {{"buckets", "8"}, {"leaf", "2"}, {"triangle", "fast"}}), "");
  EXPECT_EQ(c.name, "bvh");
  EXPECT_EQ(c.options.bvh.splitter, BvhSplitter::binned_sah);
  EXPECT_EQ(c.options.bvh.buckets, 8);
  EXPECT_EQ(c.options.bvh.max_leaf_size, 2);
  EXPECT_EQ(c.query.triangle_test, TriangleTest::moller_trumbore);
  EXPECT_EQ(apply_sweep_point(c, "bvh", {{"buckets", "exact"}}), "");
  EXPECT_EQ(c.options.bvh.splitter, BvhSplitter::exact_sah);
  EXPECT_EQ(apply_sweep_point(c, "grid", {{"lambda", "2"}}), "");
  EXPECT_EQ(c.name, "grid");
  EXPECT_FLOAT_EQ(c.options.grid.lambda, 2.0f);

  const StructureChoice before = c;
  const std::string err = apply_sweep_point(c, "kdtree", {{"depth", "8"}, {"mailbox", "maybe"}});
  EXPECT_NE(err.find("mailbox"), std::string::npos) << err;
  EXPECT_EQ(c.name, before.name);
  EXPECT_EQ(c.options.kdtree.max_depth, before.options.kdtree.max_depth);
}

TEST(SweepSeries, OneLinePerCombinationOfTheOtherParameters) {
  std::vector<SweepResult> res;
  for (const char* leaf : {"1", "4"})
    for (const char* b : {"2", "8", "exact"}) {
      SweepResult r;
      r.setting = {{"leaf", leaf}, {"buckets", b}};
      res.push_back(r);
    }
  const std::vector<SweepSeries> by_buckets = sweep_series(res, 1);
  ASSERT_EQ(by_buckets.size(), 2u);
  EXPECT_EQ(by_buckets[0].label, "leaf=1");
  EXPECT_EQ(by_buckets[0].value_index, (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(by_buckets[1].result, (std::vector<std::size_t>{3, 4, 5}));
  const std::vector<SweepSeries> by_leaf = sweep_series(res, 0);
  ASSERT_EQ(by_leaf.size(), 3u);
  EXPECT_EQ(by_leaf[2].label, "buckets=exact");
  EXPECT_EQ(by_leaf[2].result, (std::vector<std::size_t>{2, 5}));
  EXPECT_EQ(by_leaf[2].value_index, (std::vector<int>{0, 1}));

  const std::vector<ParetoPoint> pts = sweep_points(res, 1e6);
  EXPECT_EQ(pts.size(), res.size());
}

TEST(SweepFigures, ValuesComeFromTheResult) {
  SweepResult r;
  r.sah_cost = 12.5;
  r.build_ms = 3;
  r.rays_per_s = 1e6;
  r.memory_bytes = 2 * 1024 * 1024;
  r.edges.misses = 7;
  EXPECT_DOUBLE_EQ(sweep_figure_value(r, SweepFigure::sah_cost, 1e6), 12.5);
  EXPECT_DOUBLE_EQ(sweep_figure_value(r, SweepFigure::total_ms, 1e6), 1003.0);
  EXPECT_DOUBLE_EQ(sweep_figure_value(r, SweepFigure::memory, 1e6), 2.0);
  EXPECT_DOUBLE_EQ(sweep_figure_value(r, SweepFigure::edge_misses, 1e6), 7.0);
  for (int f = 0; f < kSweepFigureCount; ++f) EXPECT_STRNE(sweep_figure_name(static_cast<SweepFigure>(f)), "?");
}

TEST(RunSweepRequest, PublishesASnapshotPerSettingAndEndsDone) {
  const SweepRequest r = small_request("builtin:teapot?size=800", "buckets=2,exact triangle=watertight,fast");
  std::vector<std::size_t> seen;
  const auto last = run_sweep_request(r, 5, {}, [&](std::shared_ptr<const SweepSnapshot> s) {
    EXPECT_EQ(s->id, 5u);
    seen.push_back(s->results.size());
  });
  ASSERT_TRUE(last);
  EXPECT_EQ(last->state, SweepSnapshot::State::done) << last->error;
  ASSERT_EQ(last->results.size(), 4u);
  EXPECT_EQ(last->settings.size(), 4u);
  EXPECT_DOUBLE_EQ(last->fraction(), 1.0);
  EXPECT_EQ(last->rays, 24u * 16u);
  EXPECT_GT(last->probes, 100u);
  for (std::size_t i = 0; i + 1 < seen.size(); ++i) EXPECT_LE(seen[i], seen[i + 1]);
  EXPECT_GE(seen.size(), 5u);  // rays, then one per setting, then the end
  for (const SweepResult& res : last->results) {
    EXPECT_GT(res.build_ms, 0.0);
    EXPECT_GT(res.rays_per_s, 0.0);
    EXPECT_EQ(res.edges.probes, last->probes);
  }
  // Watertight never leaks through a shared edge; exact SAH is no worse than 2 buckets.
  EXPECT_EQ(last->results[0].edges.misses, 0u);
  EXPECT_EQ(last->results[2].edges.misses, 0u);
  EXPECT_LE(last->results[2].sah_cost, last->results[0].sah_cost);
}

// The panel's bar moves inside a setting: one slow build did not move it.
TEST(RunSweepRequest, TheFractionMovesInsideASetting) {
  SweepRequest r = small_request("builtin:teapot?size=3000", "buckets=8");
  r.structure = "octree";
  r.params = parse_sweep_params_text("octree", "depth=8,10");
  std::vector<double> between;  ///< fractions of snapshots that were strictly between two settings' ends
  const auto last = run_sweep_request(r, 3, {}, [&](std::shared_ptr<const SweepSnapshot> s) {
    const double steps = static_cast<double>(s->settings.size());
    const double f = s->fraction() * steps;
    if (s->state == SweepSnapshot::State::running && f - std::floor(f) > 1e-9) between.push_back(s->fraction());
    EXPECT_LE(s->fraction(), 1.0);
  });
  ASSERT_EQ(last->state, SweepSnapshot::State::done) << last->error;
  EXPECT_DOUBLE_EQ(last->fraction(), 1.0);
  SweepSnapshot s = *last;
  s.state = SweepSnapshot::State::running;
  s.results.resize(1);
  s.setting_fraction = 0.5;
  EXPECT_DOUBLE_EQ(s.fraction(), 0.75);
  // At most one snapshot per 0.1 s inside a setting, the first at once.
  EXPECT_FALSE(between.empty());
  for (double f : between) {
    EXPECT_GT(f, 0.0);
    EXPECT_LT(f, 1.0);
  }
}

TEST(RunSweepRequest, CancelKeepsWhatWasMeasuredAndBadInputFails) {
  const SweepRequest r = small_request("builtin:soup?size=2000", "buckets=2,4,8,16");
  int asked = 0;
  std::size_t settings_started = 0;
  const auto last = run_sweep_request(
      r, 1,
      [&] {
        ++asked;
        return settings_started < 3;  // cancel inside the third setting
      },
      [&](std::shared_ptr<const SweepSnapshot> s) {
        if (s->stage.rfind("bvh ", 0) == 0) settings_started = s->results.size() + 1;
      });
  EXPECT_EQ(last->state, SweepSnapshot::State::cancelled);
  EXPECT_EQ(last->results.size(), 2u);
  EXPECT_GT(asked, 0);
  EXPECT_LT(last->fraction(), 1.0);

  SweepRequest none = r;
  none.scene.reset();
  const auto failed = run_sweep_request(none, 2, {}, {});
  EXPECT_EQ(failed->state, SweepSnapshot::State::failed);
  EXPECT_FALSE(failed->error.empty());
}

TEST(SweepWorker, ANewRequestSupersedesAndCancelStops) {
  SweepWorker w;
  const SweepRequest slow = small_request("builtin:soup?size=20000", "buckets=2,3,4,5,6,7,8,9,10,11,12,13,14,15,16");
  const SweepRequest quick = small_request("builtin:soup?size=500", "leaf=1,2");
  const std::uint64_t a = w.request(slow);
  const std::uint64_t b = w.request(quick);
  EXPECT_GT(b, a);
  ASSERT_TRUE(eventually([&] { return !w.busy(); }));
  auto s = w.latest();
  ASSERT_TRUE(s);
  EXPECT_EQ(s->id, b);
  EXPECT_EQ(s->state, SweepSnapshot::State::done);
  EXPECT_EQ(s->results.size(), 2u);

  const std::uint64_t c = w.request(slow);
  ASSERT_TRUE(eventually([&] {
    const auto l = w.latest();
    return l && l->id == c;
  }));
  w.cancel();
  ASSERT_TRUE(eventually([&] { return !w.busy(); }));
  s = w.latest();
  EXPECT_EQ(s->id, c);
  EXPECT_EQ(s->state, SweepSnapshot::State::cancelled);
  EXPECT_LT(s->results.size(), 15u);
}

// A request shows at once as queued; a Cancel before its job starts leaves its snapshot cancelled
// (the GUI script's dump-sweep waited for ever for a snapshot of a sweep that never ran).
TEST(SweepWorker, ACancelBeforeTheJobStartsSaysCancelled) {
  SweepWorker w;
  const SweepRequest slow = small_request("builtin:soup?size=20000", "buckets=2,3,4,5,6,7,8,9,10,11,12,13,14,15,16");
  const std::uint64_t a = w.request(slow);
  const std::uint64_t b = w.request(slow);  // a is dropped or superseded; b queued or running
  auto s = w.latest();
  ASSERT_TRUE(s);
  EXPECT_EQ(s->id, b);
  EXPECT_EQ(s->structure, "bvh");
  w.cancel();
  ASSERT_TRUE(eventually([&] { return !w.busy(); }));
  s = w.latest();
  EXPECT_EQ(s->id, b) << "a's snapshot (" << a << ") replaced b's";
  EXPECT_EQ(s->state, SweepSnapshot::State::cancelled);
  EXPECT_LT(s->results.size(), 15u);
}

TEST(CalibratedBvh, BuildsWithTheMeasuredRatioAndJudgesBothTreesAlike) {
  const auto scene = scene_of("builtin:soup?size=3000");
  const SweepRequest r = small_request("builtin:soup?size=3000", "leaf=1");
  const std::vector<Ray> rays = primary_rays(r.camera, 32, 24);
  Calibration c;
  c.ns_box = 2.0;
  c.ns_triangle_watertight = 1.0;  // C_isect = 1 / (2 * 2) = 0.25: triangles are cheap here
  c.ns_triangle_fast = 0.8;
  const CalibrationReport rep = compare_calibrated_bvh(scene->scene.triangles, rays, c, QueryOptions{}, 1, 1);
  EXPECT_DOUBLE_EQ(rep.c_isect, 0.25);
  EXPECT_FLOAT_EQ(rep.with_default.c_isect, 1.0f);
  EXPECT_FLOAT_EQ(rep.with_calibrated.c_isect, 0.25f);
  EXPECT_GT(rep.with_default.build_ms, 0.0);
  EXPECT_GT(rep.with_calibrated.rays_per_s, 0.0);
  // Cheap triangles: the SAH keeps bigger leaves (fewer nodes, more tests
  // per ray) and, judged by the calibrated constants, the calibrated tree is
  // no worse (within the binned SAH's greedy slack).
  EXPECT_LT(rep.with_calibrated.nodes, rep.with_default.nodes);
  EXPECT_GT(rep.with_calibrated.prims_per_ray, rep.with_default.prims_per_ray);
  EXPECT_LE(rep.with_calibrated.sah_calibrated, rep.with_default.sah_calibrated * 1.02);

  QueryOptions fast;
  fast.triangle_test = TriangleTest::moller_trumbore;
  EXPECT_DOUBLE_EQ(compare_calibrated_bvh(scene->scene.triangles, rays, c, fast, 1, 1).c_isect, 0.2);
  Calibration broken;
  EXPECT_THROW(compare_calibrated_bvh(scene->scene.triangles, rays, broken, QueryOptions{}, 1, 1), std::runtime_error);
}

}  // namespace
}  // namespace accelviz::unity_test_app_sweep_worker
