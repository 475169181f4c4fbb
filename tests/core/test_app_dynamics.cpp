// The GUI's effects and dynamics logic (ui/app/dynamics.h): force-on
// checkboxes kept in AppConfig, the timeline clock, and DynamicsWorker
// stepping a SceneAnimator on its own thread.
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "core/scene/load.h"
#include "ui/app/dynamics.h"
#include "ui/app/script.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_app_dynamics {

using namespace accelviz;

namespace {

std::shared_ptr<const LoadedScene> loaded(const std::string& spec) {
  auto s = std::make_shared<LoadedScene>();
  s->spec = spec;
  s->scene = make_builtin(spec);
  return s;
}

std::shared_ptr<const DynamicsSnapshot> wait_done(const DynamicsWorker& w) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (w.busy() && std::chrono::steady_clock::now() < until)
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  EXPECT_FALSE(w.busy());
  return w.latest();
}

}  // namespace

TEST(AppEffects, ForcingTwoLevelSelectsTlasAndUnforcingKeepsTheChoice) {
  AppConfig c;
  ASSERT_EQ(c.structure.name, "bvh");
  EXPECT_EQ(force_effect(c, "two-level", true), "");
  EXPECT_TRUE(c.effects.two_level);
  EXPECT_EQ(c.structure.name, "tlas");
  EXPECT_EQ(force_effect(c, "two-level", false), "");
  EXPECT_FALSE(c.effects.two_level);
  EXPECT_EQ(c.structure.name, "tlas");  // the user's structure stays until they pick another

  EXPECT_EQ(force_effect(c, "shadow-rays", true), "");
  EXPECT_TRUE(c.effects.shadow_rays);
  EXPECT_EQ(force_effect(c, "shadow-rays", false), "");
  EXPECT_FALSE(c.effects.shadow_rays);
}

TEST(AppEffects, UnknownAndUnforceableEffectsAreRefusedUnchanged) {
  AppConfig c;
  const std::string unknown = force_effect(c, "reflections", true);
  EXPECT_NE(unknown.find("reflections"), std::string::npos) << unknown;
  const std::string tex = force_effect(c, "textures", true);
  EXPECT_NE(tex.find("cannot be forced"), std::string::npos) << tex;
  EXPECT_FALSE(c.effects.textures);
  EXPECT_EQ(c.structure.name, "bvh");
}

TEST(AppEffects, JsonFollowsTheDecisionsAndTheForces) {
  const Scene teapot = make_builtin("builtin:teapot?size=500");
  AppConfig c;
  nlohmann::json j = effects_json(decide_effects(teapot, c.effects));
  ASSERT_EQ(j.size(), 4u);
  EXPECT_EQ(j[1]["name"], "per-frame-updates");
  EXPECT_FALSE(j[1]["on"].get<bool>());
  ASSERT_EQ(force_effect(c, "per-frame-updates", true), "");
  j = effects_json(decide_effects(teapot, c.effects));
  EXPECT_TRUE(j[1]["on"].get<bool>());
  EXPECT_TRUE(j[1]["forced"].get<bool>());
  EXPECT_NE(j[1]["reason"].get<std::string>().find("forced on"), std::string::npos);
}

TEST(AppDynamicsPlayer, PlayingAdvancesAndWrapsPausedAsksOncePerSeek) {
  DynamicsPlayer p;
  p.duration = 2.0f;
  EXPECT_TRUE(p.tick(0.1, false));  // the first frame (t = 0)
  EXPECT_EQ(p.time(), 0.0f);
  EXPECT_FALSE(p.tick(0.1, false));  // paused: nothing new
  p.seek(5.0f);
  EXPECT_FLOAT_EQ(p.time(), 1.0f);  // wrapped into the 2 s duration
  EXPECT_FALSE(p.tick(0.0, true));  // the worker is busy: wait
  EXPECT_TRUE(p.tick(0.0, false));  // then ask
  p.playing = true;
  p.speed = 2.0f;
  EXPECT_TRUE(p.tick(0.25, false));
  EXPECT_FLOAT_EQ(p.time(), 1.5f);
  EXPECT_TRUE(p.tick(0.5, false));
  EXPECT_FLOAT_EQ(p.time(), 0.5f);  // 2.5 wrapped
}

TEST(AppDynamicsWorker, StepsTheAnimationOffThreadAndRecordsEachFrame) {
  const auto scene = loaded("builtin:dynamic?size=2400");
  DynamicsWorker w;
  w.request({scene, 0.0f});
  auto snap = wait_done(w);
  ASSERT_TRUE(snap);
  EXPECT_EQ(snap->error, "");
  EXPECT_EQ(snap->scene, scene.get());
  EXPECT_TRUE(snap->animates);
  EXPECT_GT(snap->setup_ms, 0.0);
  w.request({scene, 0.4f});
  snap = wait_done(w);
  ASSERT_EQ(snap->frames, 2u);
  ASSERT_EQ(snap->history.size(), 2u);
  const FrameStats& f = snap->history.back();
  EXPECT_FLOAT_EQ(f.time, 0.4f);
  EXPECT_GT(f.moved_instances, 0u);
  EXPECT_TRUE(f.tlas_rebuilt);
  EXPECT_GT(f.tlas_rebuild_ms, 0.0);
  EXPECT_EQ(f.refits + f.rebuilds, 1u);  // the grass
  EXPECT_GT(f.sah_refit, 0.0);
  EXPECT_GT(f.sah_rebuilt, 0.0);
}

TEST(AppDynamicsWorker, AStaticSceneForcedCostsNothingPerFrame) {
  const auto scene = loaded("builtin:teapot?size=500");
  DynamicsWorker w;
  w.request({scene, 0.0f});
  wait_done(w);
  w.request({scene, 1.0f});
  const auto snap = wait_done(w);
  ASSERT_TRUE(snap);
  EXPECT_FALSE(snap->animates);
  ASSERT_EQ(snap->history.size(), 2u);
  for (const FrameStats& f : snap->history) {
    EXPECT_FALSE(f.tlas_rebuilt);
    EXPECT_EQ(f.moved_instances, 0u);
    EXPECT_EQ(f.refits + f.rebuilds, 0u);
  }
}

TEST(AppDynamicsWorker, ARequestWithoutASceneReleasesIt) {
  DynamicsWorker w;
  w.request({loaded("builtin:dynamic?size=1200"), 0.0f});
  ASSERT_TRUE(wait_done(w));
  w.request({});
  EXPECT_FALSE(wait_done(w));
}

TEST(AppDynamicsScript, CommandsAreCheckedAtParseTime) {
  const auto ok =
      parse_script("play 3\nforce-effect two-level\nforce-effect shadow-rays off\ndump-dynamics a b.json\n", "s.txt");
  ASSERT_EQ(ok.size(), 4u);
  EXPECT_EQ(ok[0].kind, ScriptCommand::Kind::play);
  EXPECT_EQ(ok[0].x, 3);
  EXPECT_EQ(ok[1].arg, "two-level");
  EXPECT_EQ(ok[1].value, "on");
  EXPECT_EQ(ok[2].value, "off");
  EXPECT_EQ(ok[3].arg, "a b.json");
  for (const char* bad : {"play 0", "play x", "play", "force-effect textures", "force-effect glow",
                          "force-effect two-level maybe", "dump-dynamics"}) {
    try {
      parse_script(std::string("wait\n") + bad + "\n", "s.txt");
      ADD_FAILURE() << bad << " parsed";
    } catch (const ScriptError& e) {
      EXPECT_EQ(e.line(), 2) << bad;
    }
  }
}
}  // namespace unity_test_app_dynamics
