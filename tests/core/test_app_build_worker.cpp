// Background builds: a newer request cancels the older build (through its
// progress callback), only the newest result is shown, and the structure
// shown stays available, drawn and queryable, until its successor is ready.
// The builder used here blocks on a gate the test opens, so the order of
// events is forced, not timed.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>

#include "core/accel/brute_force.h"
#include "core/accel/tlas/tlas.h"
#include "core/query/camera.h"
#include "core/util/one_line.h"
#include "tests/support/refusing_accelerator.h"
#include "ui/app/app_state.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_app_build_worker {

using namespace accelviz;
using namespace std::chrono_literals;

namespace {

Scene two_triangles() {
  Scene s;
  s.triangles = {{{-1, -1, 0}, {1, -1, 0}, {0, 1, 0}}, {{-1, -1, -2}, {1, -1, -2}, {0, 1, -2}}};
  return s;
}

// A builder that reports progress until the test opens its gate for the
// build with the given bucket count (used as a build label), and throws
// BuildCancelled as soon as the progress callback says stop.
class GatedBuilder {
 public:
  BuildWorker::BuildFn fn() {
    return [this](std::span<const Triangle> tris, const StructureChoice& c, const ProgressCallback& progress) {
      const int label = c.options.bvh.buckets;
      {
        std::lock_guard lock(m_);
        started_.push_back(label);
      }
      cv_.notify_all();
      for (;;) {
        if (!progress(0.5)) {
          std::lock_guard lock(m_);
          cancelled_.push_back(label);
          cv_.notify_all();
          throw BuildCancelled();
        }
        std::unique_lock lock(m_);
        if (cv_.wait_for(lock, 1ms, [&] { return open_.count(label) > 0; })) break;
      }
      if (c.name == "fail") throw std::invalid_argument("bad options for this test");
      return std::unique_ptr<Accelerator>(std::make_unique<BruteForce>(tris));
    };
  }
  void open(int label) {
    std::lock_guard lock(m_);
    open_.insert(label);
    cv_.notify_all();
  }
  // Waits (bounded) until the build with this label has started / been cancelled.
  bool wait_started(int label) {
    return wait_for([&] { return contains(started_, label); });
  }
  bool wait_cancelled(int label) {
    return wait_for([&] { return contains(cancelled_, label); });
  }
  std::vector<int> started() {
    std::lock_guard lock(m_);
    return started_;
  }

 private:
  static bool contains(const std::vector<int>& v, int x) { return std::find(v.begin(), v.end(), x) != v.end(); }
  template <typename Pred>
  bool wait_for(Pred pred) {
    std::unique_lock lock(m_);
    return cv_.wait_for(lock, 30s, pred);
  }
  std::mutex m_;
  std::condition_variable cv_;
  std::vector<int> started_, cancelled_;
  std::set<int> open_;
};

// Polls `update` until `pred` holds (bounded: a hang fails, never a slow machine).
template <typename Pred>
bool pump(AppState& app, Pred pred) {
  const auto deadline = std::chrono::steady_clock::now() + 30s;
  while (std::chrono::steady_clock::now() < deadline) {
    app.update(64, 48);
    if (pred()) return true;
    std::this_thread::sleep_for(1ms);
  }
  return false;
}

// `loads` counts loads; the loader runs on the worker thread, hence atomic.
BuildWorker::LoadFn fake_loader(std::atomic<int>* loads = nullptr) {
  return [loads](const std::string& spec) {
    if (loads) ++*loads;
    if (spec.find("missing") != std::string::npos) throw SceneError(spec + ": no such file");
    Scene s = two_triangles();
    s.source = spec;
    return s;
  };
}

}  // namespace

TEST(AppBuildWorker, NewerRequestCancelsTheOlderBuild) {
  GatedBuilder gate;
  BuildWorker w(fake_loader(), gate.fn());
  StructureChoice a, b;
  a.options.bvh.buckets = 4;
  b.options.bvh.buckets = 8;
  const std::uint64_t ida = w.request({"scene", a, false});
  ASSERT_TRUE(gate.wait_started(4));
  EXPECT_TRUE(w.status().busy);
  const std::uint64_t idb = w.request({"scene", b, false});
  EXPECT_GT(idb, ida);
  ASSERT_TRUE(gate.wait_cancelled(4)) << "the older build was told to stop";
  ASSERT_TRUE(gate.wait_started(8));
  gate.open(8);
  std::vector<BuildOutcome> outcomes;
  const auto deadline = std::chrono::steady_clock::now() + 30s;
  while (outcomes.size() < 2 && std::chrono::steady_clock::now() < deadline) {
    for (BuildOutcome& o : w.take_outcomes()) outcomes.push_back(std::move(o));
    std::this_thread::sleep_for(1ms);
  }
  ASSERT_EQ(outcomes.size(), 2u);
  EXPECT_EQ(outcomes[0].id, ida);
  EXPECT_EQ(outcomes[0].result, BuildOutcome::Result::cancelled);
  EXPECT_EQ(outcomes[1].id, idb);
  ASSERT_EQ(outcomes[1].result, BuildOutcome::Result::built);
  EXPECT_EQ(outcomes[1].built->choice.options.bvh.buckets, 8);
  EXPECT_EQ(outcomes[1].built->scene->spec, "scene");
  EXPECT_TRUE(w.idle());
}

TEST(AppBuildWorker, QueuedRequestsCollapseToTheNewest) {
  GatedBuilder gate;
  BuildWorker w(fake_loader(), gate.fn());
  StructureChoice c;
  c.options.bvh.buckets = 2;
  w.request({"scene", c, false});
  ASSERT_TRUE(gate.wait_started(2));
  // Three more while the first runs: only the last one is ever built.
  for (int label : {3, 5, 7}) {
    c.options.bvh.buckets = label;
    w.request({"scene", c, false});
  }
  gate.open(7);
  ASSERT_TRUE(gate.wait_started(7));
  const auto deadline = std::chrono::steady_clock::now() + 30s;
  while (!w.idle() && std::chrono::steady_clock::now() < deadline) {
    w.take_outcomes();
    std::this_thread::sleep_for(1ms);
  }
  EXPECT_EQ(gate.started(), (std::vector<int>{2, 7})) << "3 and 5 were superseded before they started";
}

TEST(AppBuildWorker, TheShownStructureStaysUntilItsSuccessorIsReady) {
  GatedBuilder gate;
  AppSettings settings;
  settings.config.structure.options.bvh.buckets = 4;
  AppState app(settings, fake_loader(), gate.fn());
  app.open_scene("scene");
  gate.open(4);
  ASSERT_TRUE(pump(app, [&] { return app.current() != nullptr; }));
  const std::shared_ptr<const BuiltStructure> first = app.current();
  EXPECT_EQ(first->choice.options.bvh.buckets, 4);

  // A change: the new build runs (and is held at the gate) ...
  ASSERT_EQ(app.set_option("buckets", "8"), "");
  app.update(64, 48);
  ASSERT_TRUE(gate.wait_started(8));
  // ... while the old structure is still shown and answers queries.
  for (int i = 0; i < 20; ++i) app.update(64, 48);
  EXPECT_EQ(app.current(), first);
  const Ray ray({0.0f, 0.0f, 5.0f}, {0.0f, 0.0f, -1.0f});
  EXPECT_EQ(app.current()->accel->closest_hit(ray, {}).prim, 0u);
  EXPECT_FALSE(app.settled());

  // A newer change supersedes the pending one; only it gets shown.
  ASSERT_EQ(app.set_option("buckets", "16"), "");
  app.update(64, 48);
  ASSERT_TRUE(gate.wait_cancelled(8));
  EXPECT_EQ(app.current(), first);
  gate.open(16);
  ASSERT_TRUE(pump(app, [&] { return app.current() != first; }));
  EXPECT_EQ(app.current()->choice.options.bvh.buckets, 16);
  EXPECT_EQ(app.current()->scene, first->scene) << "same scene, not reloaded";
  EXPECT_NE(app.message().find("built bvh"), std::string::npos) << app.message();
}

TEST(AppBuildWorker, FailuresKeepWhatIsShown) {
  GatedBuilder gate;
  std::atomic<int> loads = 0;
  AppSettings settings;
  settings.config.structure.options.bvh.buckets = 4;
  AppState app(settings, fake_loader(&loads), gate.fn());
  app.open_scene("good");
  gate.open(4);
  ASSERT_TRUE(pump(app, [&] { return app.current() != nullptr; }));
  const auto first = app.current();

  // A scene that cannot be loaded: one-line error, the old scene stays.
  app.open_scene("/data/missing.glb");
  ASSERT_TRUE(pump(app, [&] { return !app.error().empty(); }));
  EXPECT_EQ(app.error(), "/data/missing.glb: no such file");
  EXPECT_EQ(app.current(), first);
  EXPECT_EQ(app.scene_spec(), "good");
  ASSERT_TRUE(pump(app, [&] { return app.settled(); }));
  EXPECT_EQ(app.take_new_errors(), std::vector<std::string>{"/data/missing.glb: no such file"});

  // A build that throws: error shown, old structure kept, and the next
  // change builds over the scene that is shown (no reload).
  const int loads_before = loads.load();
  app.config().structure.name = "fail";
  app.config().structure.options.bvh.buckets = 6;
  gate.open(6);
  ASSERT_TRUE(pump(app, [&] { return app.error().find("bad options") != std::string::npos; }));
  EXPECT_EQ(app.error(), "fail: bad options for this test");
  EXPECT_EQ(app.current(), first);
  app.config().structure.name = "bvh";
  app.config().structure.options.bvh.buckets = 10;
  gate.open(10);
  ASSERT_TRUE(pump(app, [&] { return app.current() != first; }));
  EXPECT_EQ(loads, loads_before);
  EXPECT_EQ(app.scene_spec(), "good");
}

TEST(AppBuildWorker, CancelKeepsTheShownStructureAndItsOptions) {
  GatedBuilder gate;
  AppSettings settings;
  settings.config.structure.options.bvh.buckets = 4;
  AppState app(settings, fake_loader(), gate.fn());
  app.open_scene("scene");
  gate.open(4);
  ASSERT_TRUE(pump(app, [&] { return app.current() != nullptr; }));
  const auto first = app.current();
  ASSERT_EQ(app.set_option("buckets", "12"), "");
  app.update(64, 48);
  ASSERT_TRUE(gate.wait_started(12));
  app.cancel_build();
  ASSERT_TRUE(gate.wait_cancelled(12));
  ASSERT_TRUE(pump(app, [&] { return app.settled(); }));
  EXPECT_EQ(app.current(), first);
  EXPECT_EQ(app.config().structure.options.bvh.buckets, 4) << "the panel shows what is built again";
  EXPECT_EQ(gate.started(), (std::vector<int>{4, 12})) << "the cancelled choice is not requested again";
}

TEST(AppBuildWorker, ReopeningTheSameSceneReloadsIt) {
  std::atomic<int> loads = 0;
  AppState app(AppSettings{}, fake_loader(&loads));
  app.open_scene("scene");
  ASSERT_TRUE(pump(app, [&] { return app.current() != nullptr && app.settled(); }));
  EXPECT_EQ(loads, 1);
  ASSERT_EQ(app.set_option("structure", "kdtree"), "");
  ASSERT_TRUE(pump(app, [&] { return app.current()->choice.name == "kdtree" && app.settled(); }));
  EXPECT_EQ(loads, 1) << "a structure change builds over the loaded scene";
  app.open_scene("scene");
  ASSERT_TRUE(pump(app, [&] { return loads == 2 && app.settled(); }));
  EXPECT_EQ(app.settings().recent, std::vector<std::string>{"scene"});
  EXPECT_EQ(app.settings().last_scene, "scene");
}
}  // namespace unity_test_app_build_worker

namespace unity_test_app_build_worker {
namespace {
// The promise "simulate only the effects a scene calls for": a scene that
// instances a mesh more than once opens as the two-level structure (the
// effects list says "two-level on" for it); a scene without instancing then
// goes back to the structure the app left; a structure the user picks is kept.
using accelviz::testing::RefusingAccelerator;

// The heatmap, a click's pick and a ray inspection over a structure that refuses the view's rays:
// the exceptions ended the program (the heatmap's on its worker thread); now the status line says
// why, the window settles (a script's `wait` returns), and nothing is inspected.
TEST(AppBuildWorker, AStructureThatRefusesTheRaysIsSaidNotFatal) {
  AppState app(AppSettings{}, fake_loader(),
               [](std::span<const Triangle>, const StructureChoice&, const ProgressCallback&) {
                 return std::unique_ptr<Accelerator>(std::make_unique<RefusingAccelerator>());
               });
  app.open_scene("builtin:anything");
  ASSERT_TRUE(pump(app, [&] { return app.settled() && app.current(); }));
  EXPECT_EQ(app.error(), "heatmap not traced: refusing: cannot trace this ray");
  EXPECT_FALSE(app.pick(10, 10).has_value());
  EXPECT_EQ(app.cast_ray(10, 10), "pixel 10,10 not inspected: refusing: cannot trace this ray");
  EXPECT_FALSE(app.inspection().has_value());
}

TEST(AppBuildWorker, AnOpenedScenesInstancingChoosesTheLevel) {
  AppSettings settings;
  settings.config.structure.name = "kdtree";
  AppState app(settings);
  const auto shown = [&](const std::string& spec, const std::string& name) {
    return pump(app, [&] {
      return app.settled() && app.current() && app.current()->scene->spec == spec && app.current()->choice.name == name;
    });
  };
  const std::string forest = "builtin:forest?size=400", teapot = "builtin:teapot?size=300";
  app.open_scene(forest);
  ASSERT_TRUE(shown(forest, "tlas"));
  EXPECT_EQ(app.config().structure.name, "tlas");
  EXPECT_NE(app.message().find("two-level structure (tlas) instead of kdtree"), std::string::npos) << app.message();
  app.open_scene(teapot);
  ASSERT_TRUE(shown(teapot, "kdtree"));
  EXPECT_EQ(app.config().structure.name, "kdtree");
  EXPECT_NE(app.message().find("back to kdtree from tlas"), std::string::npos) << app.message();
  // A structure change by the user is not undone, and builds once.
  app.open_scene(forest);
  ASSERT_TRUE(shown(forest, "tlas"));
  ASSERT_EQ(app.set_option("structure", "grid"), "");
  ASSERT_TRUE(shown(forest, "grid"));
  for (int i = 0; i < 20; ++i) app.update(64, 48);
  EXPECT_EQ(app.current()->choice.name, "grid");
  // tlas picked by the user on a scene without instancing stays tlas when such a scene opens again.
  app.open_scene(teapot);
  ASSERT_TRUE(shown(teapot, "grid"));
  ASSERT_EQ(app.set_option("structure", "tlas"), "");
  ASSERT_TRUE(shown(teapot, "tlas"));
  // Allowed, and said: the scene calls for one level.
  const auto* tlas = dynamic_cast<const Tlas*>(app.current()->accel.get());
  ASSERT_NE(tlas, nullptr);
  EXPECT_NE(app.message().find("no mesh is instanced twice (two-level off): tlas holds its " +
                               count_of(tlas->instances().size(), "instance")),
            std::string::npos)
      << app.message();
  app.open_scene(teapot);
  ASSERT_TRUE(pump(app, [&] { return app.settled() && !app.loading_scene(); }));
  EXPECT_EQ(app.current()->choice.name, "tlas");
}
}  // namespace
}  // namespace unity_test_app_build_worker
