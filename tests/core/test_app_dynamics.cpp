// The GUI's effects and dynamics logic (ui/app/dynamics.h): force-on
// checkboxes kept in AppConfig, the timeline clock, and DynamicsWorker
// stepping a SceneAnimator on its own thread.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <thread>

#include "core/scene/animation.h"
#include "core/scene/effects.h"
#include "core/scene/load.h"
#include "ui/app/app_state.h"
#include "ui/app/dynamics.h"
#include "ui/app/script.h"
#include "ui/app/settings.h"

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

namespace app_dynamics_frames {

template <typename Pred>
bool pump_app(AppState& app, Pred pred) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (std::chrono::steady_clock::now() < deadline) {
    app.update(48, 32);
    if (pred()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return false;
}

// The structure the view queries: its root box (over all the frame's geometry).
Aabb root_box(const BuiltStructure& b) {
  const auto box = b.nodes.box(0);
  return box ? *box : Aabb{};
}

}  // namespace app_dynamics_frames

TEST(AppDynamicsFrames, TheShownStructureIsTheFrameAndReturnsToRestAtZero) {
  using namespace app_dynamics_frames;
  AppSettings settings;
  settings.config.structure.name = "tlas";
  AppState app(settings);
  app.open_scene("builtin:dynamic?size=1200");
  ASSERT_TRUE(pump_app(app, [&] { return app.settled() && app.current(); }));
  const std::shared_ptr<const BuiltStructure> rest = app.rest();
  ASSERT_EQ(app.current(), rest);
  const Aabb rest_box = root_box(*rest);
  ASSERT_FALSE(rest_box.is_empty());

  DynamicsWorker w;
  DynamicsRequest r{rest->scene, 0.75f};
  r.structure = rest->choice;
  w.request(r);
  auto snap = wait_done(w);
  ASSERT_TRUE(snap && snap->frame);
  EXPECT_EQ(snap->error, "");
  EXPECT_FLOAT_EQ(snap->frame_time, 0.75f);
  EXPECT_EQ(snap->frame->choice.name, "tlas");
  // A frame of another scene is refused; this one is shown.
  EXPECT_FALSE(app.show_frame(snap->frame, nullptr));
  ASSERT_TRUE(app.show_frame(snap->frame, snap->scene));
  EXPECT_TRUE(app.showing_frame());
  EXPECT_EQ(app.current(), snap->frame);
  const Aabb moved_box = root_box(*app.current());
  EXPECT_FALSE(moved_box.lo == rest_box.lo && moved_box.hi == rest_box.hi);
  // The heatmap follows the frame: its request is the frame's structure.
  ASSERT_TRUE(pump_app(app, [&] { return app.settled(); }));
  EXPECT_EQ(app.heatmap()->request.structure, snap->frame);
  EXPECT_GT(app.heatmap()->summary.rays, 0u);

  // Scrubbing back to 0: the frame is the rest pose again.
  r.time = 0.0f;
  w.request(r);
  snap = wait_done(w);
  ASSERT_TRUE(snap && snap->frame);
  ASSERT_TRUE(app.show_frame(snap->frame, snap->scene));
  const Aabb back = root_box(*app.current());
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(back.lo[a], rest_box.lo[a], 1e-4f * (1.0f + std::abs(rest_box.lo[a])));
    EXPECT_NEAR(back.hi[a], rest_box.hi[a], 1e-4f * (1.0f + std::abs(rest_box.hi[a])));
  }
  // Back to the build.
  app.show_rest();
  EXPECT_EQ(app.current(), rest);
  EXPECT_FALSE(app.showing_frame());
}

TEST(AppDynamicsFrames, PosedSceneMovesInstancesAndDeformsAndIsRestAtZero) {
  const Scene rest = make_builtin("builtin:dynamic?size=1200");
  const Scene at0 = posed_scene(rest, 0.0f);
  ASSERT_EQ(at0.triangles.size(), rest.triangles.size());
  // Rigid instances are at rest at t = 0; the deformed mesh (grass) sways
  // at every t, so it is checked against deformed_triangles().
  ASSERT_EQ(rest.deformers.size(), 1u);
  const MeshDeformer& d = rest.deformers[0];
  std::size_t rigid = 0, same = 0, deformed = 0;
  for (const Instance& inst : rest.instances) {
    if (inst.mesh == d.mesh) {
      const std::vector<Triangle> want = deformed_triangles(rest.meshes[d.mesh], d, 0.0f);
      ASSERT_EQ(want.size(), inst.triangle_count);
      for (std::size_t k = 0; k < want.size(); ++k)
        deformed += glm::length(at0.triangles[inst.first_triangle + k].v1 -
                                glm::vec3(inst.transform * glm::vec4(want[k].v1, 1.0f))) < 1e-4f;
      continue;
    }
    for (std::uint32_t k = inst.first_triangle; k < inst.first_triangle + inst.triangle_count; ++k) {
      ++rigid;
      same += glm::length(at0.triangles[k].v0 - rest.triangles[k].v0) < 1e-4f;
    }
  }
  EXPECT_GT(rigid, 0u);
  EXPECT_EQ(same, rigid);
  EXPECT_EQ(deformed, rest.triangles.size() - rigid);
  const Scene later = posed_scene(rest, 0.75f);
  ASSERT_EQ(later.triangles.size(), rest.triangles.size());
  std::size_t moved = 0;
  for (std::size_t i = 0; i < rest.triangles.size(); ++i)
    moved += glm::length(later.triangles[i].v0 - rest.triangles[i].v0) > 1e-3f;
  EXPECT_GT(moved, rest.triangles.size() / 10);
}

TEST(AppShadowRays, TheHeatmapTracesThemOnlyWhenLightsOrForcedAndCountsThemApart) {
  using namespace app_dynamics_frames;
  AppSettings settings;
  AppState app(settings, [](const std::string& spec) {
    Scene sc = make_builtin(spec);
    sc.lights.clear();  // a static scene without lights
    return sc;
  });
  app.open_scene("builtin:teapot?size=400");
  ASSERT_TRUE(pump_app(app, [&] { return app.settled() && app.heatmap() && app.heatmap()->complete; }));
  ASSERT_TRUE(app.scene()->lights.empty());
  nlohmann::json v = app.stats_json()["view"];
  ASSERT_GT(v["hits"].get<std::uint64_t>(), 0u);
  EXPECT_EQ(v["shadow_rays"].get<std::uint64_t>(), 0u);  // static, no lights: none
  const double primary_nodes = v["mean_nodes"].get<double>();

  // Forced on: one synthetic light, one shadow ray per primary hit, counted apart.
  ASSERT_EQ(force_effect(app.config(), "shadow-rays", true), "");
  ASSERT_TRUE(pump_app(
      app, [&] { return app.settled() && app.heatmap()->complete && !app.heatmap()->request.shadow_lights.empty(); }));
  v = app.stats_json()["view"];
  EXPECT_EQ(app.heatmap()->request.shadow_lights.size(), 1u);
  EXPECT_EQ(v["shadow_rays"].get<std::uint64_t>(), v["hits"].get<std::uint64_t>());
  EXPECT_GT(v["mean_shadow_nodes"].get<double>(), 0.0);
  EXPECT_DOUBLE_EQ(v["mean_nodes"].get<double>(), primary_nodes);  // the primary figures are unchanged
  std::uint64_t per_pixel = 0;
  for (const PixelFigures& p : app.heatmap()->pixels) {
    EXPECT_EQ(p.shadow_rays, p.prim != kInvalidId ? 1u : 0u);
    per_pixel += p.shadow_rays;
  }
  EXPECT_EQ(per_pixel, v["shadow_rays"].get<std::uint64_t>());

  // Off again: none.
  ASSERT_EQ(force_effect(app.config(), "shadow-rays", false), "");
  ASSERT_TRUE(pump_app(
      app, [&] { return app.settled() && app.heatmap()->complete && app.heatmap()->request.shadow_lights.empty(); }));
  EXPECT_EQ(app.stats_json()["view"]["shadow_rays"].get<std::uint64_t>(), 0u);
}

TEST(AppShadowRays, SceneLightsAreUsedAsTheyAre) {
  Scene s = make_builtin("builtin:teapot?size=400");
  EXPECT_TRUE(shadow_lights(s, false).empty());
  Light l;
  l.kind = Light::Kind::directional;
  l.direction = {0.0f, -1.0f, 0.0f};
  s.lights = {l, l};
  EXPECT_TRUE(shadow_rays_wanted(s, {}));
  const std::vector<Light> used = shadow_lights(s, true);
  ASSERT_EQ(used.size(), 2u);
  EXPECT_EQ(used[0].kind, Light::Kind::directional);
  // A directional light's shadow ray runs upward from the hit, to infinity.
  Ray primary({0.0f, 5.0f, 0.0f}, {0.0f, -1.0f, 0.0f});
  Hit h;
  h.t = 5.0f;
  h.prim = 0;
  h.ng = {0.0f, 1.0f, 0.0f};
  const Ray sr = shadow_ray(primary, h, used[0]);
  EXPECT_GT(sr.direction.y, 0.0f);
  EXPECT_GT(sr.origin.y, 0.0f);
  EXPECT_TRUE(std::isinf(sr.tmax));
}

TEST(AppEffectSettings, ForcesAreSavedAndRestored) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("accelviz_effects_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  AppSettings s;
  ASSERT_EQ(force_effect(s.config, "shadow-rays", true), "");
  ASSERT_EQ(force_effect(s.config, "two-level", true), "");
  const std::filesystem::path file = settings_file(dir);
  ASSERT_EQ(save_settings(file, s), "");
  const LoadedSettings loaded = load_settings(file);
  std::filesystem::remove_all(dir);
  EXPECT_EQ(loaded.error, "");
  EXPECT_TRUE(loaded.settings.config.effects.shadow_rays);
  EXPECT_FALSE(loaded.settings.config.effects.per_frame_updates);
  EXPECT_TRUE(loaded.settings.config.effects.two_level);
  EXPECT_EQ(loaded.settings.config.structure.name, "tlas");
  // A file without "effects" (older) keeps the defaults: nothing forced.
  const AppSettings old = settings_from_json(nlohmann::json{{"version", 1}});
  EXPECT_FALSE(old.config.effects.shadow_rays || old.config.effects.per_frame_updates || old.config.effects.two_level);
  // Bad entries: one line naming the key.
  for (const auto& [text, problem] : std::vector<std::pair<const char*, const char*>>{
           {R"({"effects": {"glow": true}})", "effects.glow: unknown effect"},
           {R"({"effects": {"two-level": "yes"}})", "effects.two-level: expected true or false"},
           {R"({"effects": [1]})", "effects: expected an object"}}) {
    try {
      settings_from_json(nlohmann::json::parse(text));
      ADD_FAILURE() << text;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(problem), std::string::npos) << e.what();
    }
  }
}

}  // namespace unity_test_app_dynamics
