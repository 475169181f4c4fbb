// RobustnessWorker (ui/app/robustness_worker.h): the Robustness panel's lab
// runs on a worker thread, publishes its result, and is superseded/cancelled.
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "core/accel/factory.h"
#include "core/scene/load.h"
#include "ui/app/robustness_worker.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_app_robustness_worker {

using namespace accelviz;

namespace {

std::shared_ptr<const LoadedScene> teapot() {
  auto s = std::make_shared<LoadedScene>();
  s->spec = "builtin:teapot?size=1000";
  s->scene = make_builtin(s->spec);
  return s;
}

std::shared_ptr<const RobustnessSnapshot> wait_done(const RobustnessWorker& w) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (w.busy() && std::chrono::steady_clock::now() < until)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  EXPECT_FALSE(w.busy());
  return w.latest();
}

}  // namespace

TEST(RobustnessWorker, RunsTheLabInTheBackgroundAndPublishes) {
  RobustnessWorker w;
  EXPECT_EQ(w.latest(), nullptr);
  RobustnessRequest r;
  r.scene = teapot();
  r.options.rays = 2000;
  r.options.structure = "kdtree";
  const std::uint64_t id = w.request(r);
  const auto snap = wait_done(w);
  ASSERT_NE(snap, nullptr);
  EXPECT_EQ(snap->id, id);
  EXPECT_EQ(snap->state, RobustnessSnapshot::State::done);
  ASSERT_TRUE(snap->result.has_value());
  EXPECT_EQ(snap->result->rays, 2000u);
  EXPECT_EQ(snap->result->variants.size(), 6u);
  EXPECT_EQ(snap->scene, "builtin:teapot?size=1000");
  // The worker publishes what the lab computes on the calling thread.
  const LabResult direct = run_robustness_lab(r.scene->scene.triangles, r.options);
  ASSERT_EQ(direct.variants.size(), snap->result->variants.size());
  for (std::size_t v = 0; v < direct.variants.size(); ++v) {
    EXPECT_EQ(snap->result->variants[v].name, direct.variants[v].name);
    EXPECT_EQ(snap->result->variants[v].misses, direct.variants[v].misses);
    EXPECT_EQ(snap->result->variants[v].double_hits, direct.variants[v].double_hits);
    EXPECT_EQ(snap->result->variants[v].per_ray, direct.variants[v].per_ray);
  }
  // Watertight + padded slab leaves far fewer holes than Moller-Trumbore.
  EXPECT_LT(snap->result->variants[3].misses * 4, snap->result->variants[0].misses);
}

TEST(RobustnessWorker, BadStructureFailsWithOneLine) {
  RobustnessWorker w;
  RobustnessRequest r;
  r.scene = teapot();
  r.options.rays = 100;
  r.options.structure = "voxels";
  w.request(r);
  const auto snap = wait_done(w);
  ASSERT_NE(snap, nullptr);
  EXPECT_EQ(snap->state, RobustnessSnapshot::State::failed);
  EXPECT_NE(snap->error.find("voxels"), std::string::npos);
  EXPECT_EQ(snap->error.find('\n'), std::string::npos);
}

// The panel offers the own-traversal box for every structure but voxels and
// tlas, and the lab runs each structure it is offered for.
TEST(RobustnessWorker, TheOwnTraversalIsOfferedWhereTheLabRunsIt) {
  EXPECT_FALSE(lab_times_own_traversal("voxels"));
  EXPECT_FALSE(lab_times_own_traversal("tlas"));
  const auto scene = teapot();
  for (const std::string& name : structure_names()) {
    if (!lab_times_own_traversal(name)) continue;
    LabOptions o;
    o.rays = 200;
    o.structure = name;
    const LabResult res = run_robustness_lab(scene->scene.triangles, o);
    bool own = false;
    for (const LabVariant& v : res.variants) own |= v.own_structure;
    EXPECT_TRUE(own) << name;
  }
}

TEST(RobustnessWorker, ANewRequestSupersedesAndCancelStops) {
  RobustnessWorker w;
  RobustnessRequest big;
  big.scene = teapot();
  big.options.rays = 400000;
  w.request(big);
  RobustnessRequest small = big;
  small.options.rays = 500;
  const std::uint64_t id = w.request(small);
  const auto snap = wait_done(w);
  ASSERT_NE(snap, nullptr);
  EXPECT_EQ(snap->id, id);
  ASSERT_TRUE(snap->result.has_value());
  EXPECT_EQ(snap->result->rays, 500u);
  w.request(big);
  w.cancel();
  const auto c = wait_done(w);
  ASSERT_NE(c, nullptr);
  EXPECT_NE(c->state, RobustnessSnapshot::State::running)
      << "id " << c->id << " error " << c->error << " result " << c->result.has_value();
  EXPECT_NE(c->state, RobustnessSnapshot::State::failed);
}
}  // namespace unity_test_app_robustness_worker
