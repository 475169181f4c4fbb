// The GUI's effects and dynamics logic (ui/app/dynamics.h): force-on
// checkboxes kept in AppConfig, the timeline clock, and DynamicsWorker
// stepping a SceneAnimator on its own thread.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <glm/gtc/matrix_transform.hpp>
#include <set>
#include <thread>
#include <tuple>

#include "core/accel/tlas/tlas.h"
#include "core/accel/tlas/tlas_overlap.h"
#include "core/scene/animation.h"
#include "core/scene/effects.h"
#include "core/scene/load.h"
#include "tests/support/temp_dir.h"
#include "ui/app/app_state.h"
#include "ui/app/dynamics.h"
#include "ui/app/instance_colors.h"
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

AppSettings tlas_settings() {
  AppSettings settings;
  settings.config.structure.name = "tlas";
  return settings;
}

}  // namespace app_dynamics_frames

// An AppState showing builtin:dynamic?size=1200 built as tlas, settled.
class AppDynamicsOnTlas : public ::testing::Test {
 protected:
  void SetUp() override {
    app.open_scene("builtin:dynamic?size=1200");
    ASSERT_TRUE(app_dynamics_frames::pump_app(app, [&] { return app.settled() && app.current(); }));
  }
  AppState app{app_dynamics_frames::tlas_settings()};
};

TEST_F(AppDynamicsOnTlas, TheShownStructureIsTheFrameAndReturnsToRestAtZero) {
  using namespace app_dynamics_frames;
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
  const test_support::TempDir tmp("effects");
  const std::filesystem::path dir = tmp.path() / "accelviz";  // not there yet: saving makes it
  AppSettings s;
  ASSERT_EQ(force_effect(s.config, "shadow-rays", true), "");
  ASSERT_EQ(force_effect(s.config, "two-level", true), "");
  const std::filesystem::path file = settings_file(dir);
  ASSERT_EQ(save_settings(file, s), "");
  const LoadedSettings loaded = load_settings(file);
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

// ---- issue 10 views: per-frame overlap, the animator's own tree, TLAS/BLAS boxes, instance colours ----

namespace app_dynamics_views {

// The animator's structure options for a `tlas` choice, as the worker and
// the factory build them (a fresh Tlas over a pose must use the same).
TlasOptions tlas_options_of(const StructureChoice& c) {
  TlasOptions to;
  to.blas = c.options.bvh;
  if (to.blas.threads == 0) to.blas.threads = c.options.threads;
  to.blas.compute_epo = false;
  to.tlas = to.blas;
  return to;
}

// A tiny instanced scene: one 2x2x2-triangle mesh (a strip of 8), placed
// three times, the middle one rotated and scaled.
Scene three_instances() {
  Scene s;
  Mesh m;
  m.name = "strip";
  for (int i = 0; i <= 4; ++i) {
    m.positions.push_back({static_cast<float>(i), 0.0f, 0.0f});
    m.positions.push_back({static_cast<float>(i), 1.0f, 0.2f * static_cast<float>(i)});
  }
  for (std::uint32_t i = 0; i < 4; ++i) {
    m.indices.push_back({2 * i, 2 * i + 2, 2 * i + 1});
    m.indices.push_back({2 * i + 1, 2 * i + 2, 2 * i + 3});
  }
  s.meshes.push_back(m);
  const glm::mat4 places[3] = {
      glm::translate(glm::mat4(1.0f), glm::vec3(0.0f, 0.0f, 0.0f)),
      glm::scale(
          glm::rotate(glm::translate(glm::mat4(1.0f), glm::vec3(10.0f, 0.0f, 0.0f)), 0.7f, glm::vec3(0.0f, 1.0f, 0.0f)),
          glm::vec3(1.0f, 2.0f, 1.0f)),
      glm::translate(glm::mat4(1.0f), glm::vec3(0.0f, 5.0f, 3.0f)),
  };
  for (std::uint32_t i = 0; i < 3; ++i) {
    Node n;
    n.local = places[i];
    n.mesh = 0;
    s.nodes.push_back(n);
    s.roots.push_back(static_cast<int>(i));
    Instance inst;
    inst.mesh = 0;
    inst.node = i;
    inst.transform = places[i];
    s.instances.push_back(inst);
  }
  s.flatten();
  return s;
}

}  // namespace app_dynamics_views

TEST(AppDynamicsViews, InstanceOverlapIsMeasuredPerFrameOnThatFramesInstances) {
  using namespace app_dynamics_views;
  const auto scene = loaded("builtin:dynamic?size=1200");
  DynamicsWorker w;
  const float times[] = {0.0f, 0.5f, 1.1f, 1.9f};
  for (const float t : times) {
    w.request({scene, t});
    wait_done(w);
  }
  const auto snap = w.latest();
  ASSERT_TRUE(snap);
  ASSERT_EQ(snap->error, "");
  ASSERT_EQ(snap->history.size(), 4u);
  std::set<double> distinct;
  for (std::size_t i = 0; i < 4; ++i) {
    const FrameStats& f = snap->history[i];
    // The same figure from a two-level structure built afresh over the
    // scene posed at that time (the worker's animator uses the defaults).
    const Scene posed = posed_scene(scene->scene, f.time);
    const Tlas fresh(posed, tlas_options_of(StructureChoice{}));
    const InstanceOverlap want = instance_overlap(fresh);
    EXPECT_EQ(f.overlap.instances, want.instances) << i;
    EXPECT_EQ(f.overlap.overlapping_pairs, want.overlapping_pairs) << i;
    EXPECT_NEAR(f.overlap.area_ratio, want.area_ratio, 1e-9 * (1.0 + want.area_ratio)) << i;
    EXPECT_NEAR(f.overlap.volume_ratio, want.volume_ratio, 1e-9 * (1.0 + want.volume_ratio)) << i;
    EXPECT_GT(f.overlap.area_ratio, 0.0) << i;
    distinct.insert(f.overlap.area_ratio);
  }
  EXPECT_GE(distinct.size(), 3u) << "the overlap should change as the boxes fly";
}

TEST(AppDynamicsViews, TheShownTlasFrameIsTheAnimatorsOwnTree) {
  using namespace app_dynamics_views;
  const auto scene = loaded("builtin:dynamic?size=1200");
  StructureChoice choice;
  choice.name = "tlas";
  choice.options.bvh.max_leaf_size = 2;  // not the default: the animator must take the view's options
  // The reference: an animator of our own, stepped through the same times.
  Tlas ref(scene->scene, tlas_options_of(choice));
  SceneAnimator animator(scene->scene, ref, AnimatorOptions{});
  DynamicsWorker w;
  std::shared_ptr<const BuiltStructure> first;
  double first_sah = 0.0;
  std::vector<Aabb> first_tlas_boxes;
  for (const float t : {0.3f, 1.4f, 2.6f}) {
    DynamicsRequest r{scene, t};
    r.structure = choice;
    w.request(r);
    const auto snap = wait_done(w);
    ASSERT_TRUE(snap && snap->frame);
    ASSERT_EQ(snap->error, "");
    const FrameStats f = animator.step(t);
    EXPECT_TRUE(snap->frame_is_animator_tree);
    const auto* shown = dynamic_cast<const Tlas*>(snap->frame->accel.get());
    ASSERT_NE(shown, nullptr);
    // Node count and SAH of the shown tree equal the animator's at this frame.
    EXPECT_EQ(shown->build_stats().node_count, ref.build_stats().node_count) << t;
    EXPECT_DOUBLE_EQ(shown->build_stats().sah_cost, ref.build_stats().sah_cost) << t;
    EXPECT_EQ(snap->frame->nodes.size(), StructureNodes::of(ref).size()) << t;
    // The grass BLAS is the refitted one the plots measure (not a fresh build).
    const FrameStats& g = snap->history.back();
    ASSERT_EQ(g.refits, 1u);
    ASSERT_EQ(f.refits, 1u);
    const int grass = shown->blas_of_mesh(scene->scene.deformers[0].mesh);
    ASSERT_GE(grass, 0);
    const double shown_grass = shown->blas(static_cast<std::size_t>(grass)).build_stats().sah_cost;
    EXPECT_DOUBLE_EQ(g.sah_refit, f.sah_refit) << t;
    if (g.rebuilds == 0) {
      EXPECT_DOUBLE_EQ(shown_grass, g.sah_refit) << t;
      EXPECT_NE(shown_grass, g.sah_rebuilt) << t << ": the refitted tree, not a rebuild";
    } else {
      EXPECT_DOUBLE_EQ(shown_grass, g.sah_rebuilt) << t;
    }
    if (!first) {
      first = snap->frame;
      first_sah = shown->build_stats().sah_cost;
      const auto* ft = dynamic_cast<const Tlas*>(first->accel.get());
      for (const BvhNode& n : ft->tlas_nodes()) first_tlas_boxes.push_back(n.bounds);
    }
  }
  // The first frame stays as it was while the animator moved on (snapshots
  // share BLASes copy-on-write).
  const auto* ft = dynamic_cast<const Tlas*>(first->accel.get());
  EXPECT_DOUBLE_EQ(ft->build_stats().sah_cost, first_sah);
  ASSERT_EQ(ft->tlas_nodes().size(), first_tlas_boxes.size());
  for (std::size_t i = 0; i < first_tlas_boxes.size(); ++i) {
    EXPECT_EQ(ft->tlas_nodes()[i].bounds.lo, first_tlas_boxes[i].lo);
    EXPECT_EQ(ft->tlas_nodes()[i].bounds.hi, first_tlas_boxes[i].hi);
  }
  const int grass = ft->blas_of_mesh(scene->scene.deformers[0].mesh);
  EXPECT_NE(&ft->blas(static_cast<std::size_t>(grass)), &ref.blas(static_cast<std::size_t>(grass)));
}

TEST(AppDynamicsViews, TlasSnapshotsKeepTheirBlasWhenTheOriginalIsRefitted) {
  const Scene s = make_builtin("builtin:dynamic?size=600");
  Tlas t(s);
  const std::uint32_t mesh = s.deformers[0].mesh;
  const std::size_t b = static_cast<std::size_t>(t.blas_of_mesh(mesh));
  const std::shared_ptr<const Tlas> snap = t.snapshot();
  const Bvh* shared = &snap->blas(b);
  EXPECT_EQ(shared, &t.blas(b));  // shared until one side changes
  const std::vector<Aabb> before = [&] {
    std::vector<Aabb> v;
    for (const BvhNode& n : snap->blas(b).nodes()) v.push_back(n.bounds);
    return v;
  }();
  t.refit_blas(b, deformed_triangles(s.meshes[mesh], s.deformers[0], 0.8f));
  EXPECT_NE(&t.blas(b), shared);
  EXPECT_EQ(&snap->blas(b), shared);
  bool moved = false;
  for (std::size_t i = 0; i < before.size(); ++i) {
    EXPECT_EQ(snap->blas(b).nodes()[i].bounds.lo, before[i].lo);
    moved |= !(t.blas(b).nodes()[i].bounds.hi == before[i].hi);
  }
  EXPECT_TRUE(moved);
  // Unshared, a refit works in place.
  const Bvh* own = &t.blas(b);
  t.refit_blas(b, deformed_triangles(s.meshes[mesh], s.deformers[0], 1.2f));
  EXPECT_EQ(&t.blas(b), own);
}

TEST(AppDynamicsViews, TlasAndBlasBoxSetsDifferWithTheExpectedCounts) {
  using namespace app_dynamics_views;
  const Scene s = three_instances();
  TlasOptions to;
  to.blas.max_leaf_size = 1;  // 8 triangles: 8 leaves, 15 nodes per BLAS
  to.blas.leaf_size_cap = 1;
  to.tlas = to.blas;
  const Tlas t(s, to);
  ASSERT_EQ(t.blas_count(), 1u);
  const std::size_t blas_nodes = t.blas(0).nodes().size();
  ASSERT_EQ(blas_nodes, 15u);
  const StructureNodes top = StructureNodes::of(t);

  // Leaves: the top level's are the three instance boxes, each naming its instance.
  NodeSelection leaves;
  leaves.mode = BoxMode::leaves;
  const auto tl = top.select(leaves, 1000);
  ASSERT_EQ(tl.boxes.size(), 3u);
  std::set<std::uint32_t> named;
  for (const NodeBox& b : tl.boxes) named.insert(b.instance);
  EXPECT_EQ(named, (std::set<std::uint32_t>{0, 1, 2}));
  // ...the bottom level's, every instance's eight BLAS leaves in world space.
  const auto bl = select_blas_boxes(t, leaves, 1000);
  ASSERT_EQ(bl.boxes.size(), 24u);
  EXPECT_EQ(bl.matched, 24u);
  EXPECT_FALSE(bl.truncated);
  for (std::size_t i = 0; i < bl.boxes.size(); ++i) {
    const NodeBox& b = bl.boxes[i];
    ASSERT_EQ(b.instance, i / 8);
    EXPECT_TRUE(b.leaf);
    // A leaf holds one triangle: its world box holds that world triangle
    // (one of the instance's flattened triangles), and is exactly the
    // triangle's box under a translation (instances 0 and 2; the rotated
    // instance 1 gets the box of the rotated object box's corners).
    bool inside = false, equal = false;
    const Instance& inst = s.instances[b.instance];
    for (std::uint32_t k = inst.first_triangle; k < inst.first_triangle + inst.triangle_count; ++k) {
      const Aabb w = s.triangles[k].bounds();
      if (glm::all(glm::lessThanEqual(b.bounds.lo, w.lo + 1e-4f)) &&
          glm::all(glm::greaterThanEqual(b.bounds.hi, w.hi - 1e-4f)))
        inside = true;
      if (glm::all(glm::lessThan(glm::abs(w.lo - b.bounds.lo), glm::vec3(1e-4f))) &&
          glm::all(glm::lessThan(glm::abs(w.hi - b.bounds.hi), glm::vec3(1e-4f))))
        equal = true;
    }
    EXPECT_TRUE(inside) << "box " << i;
    if (b.instance != 1) {
      EXPECT_TRUE(equal) << "box " << i;
    }
  }
  // Depth 0: one TLAS root against three BLAS roots (each instance's world box).
  NodeSelection root;
  const auto t0 = top.select(root, 1000);
  const auto b0 = select_blas_boxes(t, root, 1000);
  ASSERT_EQ(t0.boxes.size(), 1u);
  ASSERT_EQ(b0.boxes.size(), 3u);
  for (const NodeBox& b : b0.boxes) {
    const Aabb& w = t.instances()[b.instance].world_bounds;  // padded by a few ulps
    EXPECT_TRUE(w.contains(b.bounds)) << b.instance;
    EXPECT_NEAR(w.surface_area(), b.bounds.surface_area(), 1e-3f * w.surface_area()) << b.instance;
  }
  // One instance only; an instance out of range selects nothing.
  const auto one = select_blas_boxes(t, leaves, 1000, 1);
  ASSERT_EQ(one.boxes.size(), 8u);
  for (const NodeBox& b : one.boxes) EXPECT_EQ(b.instance, 1u);
  EXPECT_TRUE(select_blas_boxes(t, leaves, 1000, 3).boxes.empty());
  // The box limit: whole instances only (two of three fit in 20), all counted.
  const auto cut = select_blas_boxes(t, leaves, 20);
  EXPECT_EQ(cut.boxes.size(), 16u);
  EXPECT_TRUE(cut.truncated);
  EXPECT_EQ(cut.matched, 24u);
  // ...and a first instance larger than the limit is cut at it.
  EXPECT_EQ(select_blas_boxes(t, leaves, 5).boxes.size(), 5u);
  EXPECT_EQ(blas_max_depth(t), t.blas(0).build_stats().max_depth);
}

TEST_F(AppDynamicsOnTlas, FramingAtTheBlasLevelFramesTheChosenInstanceOrSubtree) {
  const auto* tlas = dynamic_cast<const Tlas*>(app.current()->accel.get());
  ASSERT_NE(tlas, nullptr);
  ViewSettings& v = app.config().view;
  v.box_level = BoxLevel::blas;
  v.box_instance = 5;
  app.frame_selection();  // depth mode: instance 5's world box
  const Aabb inst = tlas->instances()[5].world_bounds;
  EXPECT_LT(glm::length(app.view_camera().orbit.pivot - inst.center()), 1e-5f);
  v.box_mode = BoxMode::subtree;
  v.box_node = 1;  // the root's first child in instance 5's BLAS
  app.frame_selection();
  NodeSelection sel;
  sel.mode = BoxMode::subtree;
  sel.node = 1;
  const auto boxes = select_blas_boxes(*tlas, sel, 1000, 5);
  ASSERT_FALSE(boxes.boxes.empty());
  EXPECT_LT(glm::length(app.view_camera().orbit.pivot - boxes.boxes[0].bounds.center()), 1e-5f);
  EXPECT_GT(glm::length(app.view_camera().orbit.pivot - inst.center()), 0.0f);
}

TEST(AppDynamicsViews, InstanceColoursAreStableDistinctAndFollowTheTriangleRanges) {
  using namespace app_dynamics_views;
  std::set<std::tuple<int, int, int>> seen;
  for (std::uint32_t id = 0; id < 200; ++id) {
    const glm::vec3 c = instance_color(id);
    EXPECT_EQ(c, instance_color(id));                                              // stable
    EXPECT_GE(std::max({c.x, c.y, c.z}), 0.74f) << id;                             // bright
    EXPECT_GT(std::max({c.x, c.y, c.z}) - std::min({c.x, c.y, c.z}), 0.3f) << id;  // never grey
    seen.insert({static_cast<int>(c.x * 255), static_cast<int>(c.y * 255), static_cast<int>(c.z * 255)});
  }
  EXPECT_EQ(seen.size(), 200u);
  const Scene s = three_instances();
  const std::vector<glm::vec3> tri = triangle_instance_colors(s);
  ASSERT_EQ(tri.size(), s.triangles.size());
  for (std::uint32_t i = 0; i < 3; ++i)
    for (std::uint32_t k = 0; k < s.instances[i].triangle_count; ++k)
      EXPECT_EQ(tri[s.instances[i].first_triangle + k], instance_color(i));
}

}  // namespace unity_test_app_dynamics
