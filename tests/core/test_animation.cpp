// Animation (core/scene/animation.h) and effects by scene
// (core/scene/effects.h): channel sampling against hand-computed TRS at
// chosen times for linear (with quaternion slerp), step and cubic spline;
// world transforms through the node hierarchy; the per-frame update touches
// only what moved (rigid: TLAS only; deforming: BLAS refit or rebuild);
// refit-then-query equals rebuild-then-query; and the effect counters: a
// static scene without lights traces zero shadow rays and does zero refits,
// a light turns shadow rays on, an instanced scene builds each unique mesh once.
#include <gtest/gtest.h>

#include <cmath>
#include <glm/gtc/matrix_transform.hpp>
#include <limits>

#include "core/accel/bvh/bvh.h"
#include "core/accel/tlas/tlas.h"
#include "core/query/camera.h"
#include "core/scene/animation.h"
#include "core/scene/effects.h"
#include "core/scene/load.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_animation {

using namespace accelviz;

namespace {

AnimationChannel channel(AnimationChannel::Path path, AnimationChannel::Interpolation interp, std::vector<float> times,
                         std::vector<glm::vec4> values) {
  AnimationChannel c;
  c.node = 0;
  c.path = path;
  c.interpolation = interp;
  c.times = std::move(times);
  c.values = std::move(values);
  return c;
}

void expect_near(const glm::vec4& a, const glm::vec4& b, float eps = 1e-5f) {
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(a[i], b[i], eps) << "component " << i;
}

using P = AnimationChannel::Path;
using I = AnimationChannel::Interpolation;

}  // namespace

TEST(AnimationSampling, LinearTranslationAtChosenTimes) {
  const auto c = channel(P::translation, I::linear, {1.0f, 3.0f, 4.0f}, {{0, 0, 0, 0}, {4, -2, 8, 0}, {4, 0, 8, 0}});
  expect_near(sample_channel(c, 0.0f), {0, 0, 0, 0});      // before the first key: clamped
  expect_near(sample_channel(c, 1.5f), {1, -0.5f, 2, 0});  // a quarter of the way from key 0 to key 1
  expect_near(sample_channel(c, 3.0f), {4, -2, 8, 0});
  expect_near(sample_channel(c, 3.25f), {4, -1.5f, 8, 0});
  expect_near(sample_channel(c, 9.0f), {4, 0, 8, 0});  // after the last: clamped
}

TEST(AnimationSampling, LinearRotationIsSlerp) {
  // 0 and 90 degrees about +z; at s = 1/3 slerp gives exactly 30 degrees
  // (linear interpolation of the components would not).
  const float h = std::sqrt(0.5f);
  const auto c = channel(P::rotation, I::linear, {0.0f, 3.0f}, {{0, 0, 0, 1}, {0, 0, h, h}});
  const float a = glm::radians(30.0f) / 2.0f;
  expect_near(sample_channel(c, 1.0f), {0, 0, std::sin(a), std::cos(a)});
  // The short way round: a key of -q is the same rotation.
  const auto neg = channel(P::rotation, I::linear, {0.0f, 3.0f}, {{0, 0, 0, 1}, {0, 0, -h, -h}});
  const glm::vec4 q = sample_channel(neg, 1.0f);
  EXPECT_NEAR(std::abs(q.w), std::cos(a), 1e-5f);
  EXPECT_NEAR(std::abs(q.z), std::sin(a), 1e-5f);
}

TEST(AnimationSampling, StepHoldsTheEarlierKey) {
  const auto c = channel(P::scale, I::step, {0.0f, 1.0f, 2.0f}, {{1, 1, 1, 0}, {2, 2, 2, 0}, {3, 3, 3, 0}});
  expect_near(sample_channel(c, 0.999f), {1, 1, 1, 0});
  expect_near(sample_channel(c, 1.0f), {2, 2, 2, 0});
  expect_near(sample_channel(c, 1.7f), {2, 2, 2, 0});
  expect_near(sample_channel(c, 2.5f), {3, 3, 3, 0});
}

TEST(AnimationSampling, CubicSplineMatchesHermiteByHand) {
  // Keys at t = 0 (value 0, out-tangent 2) and t = 2 (value 4, in-tangent -1).
  // glTF: p(s) = (2s^3-3s^2+1) p0 + td (s^3-2s^2+s) b0 + (-2s^3+3s^2) p1 + td (s^3-s^2) a1, td = 2.
  // At t = 0.5: s = 0.25: h00 = 0.84375, h10 = 0.140625, h01 = 0.15625, h11 = -0.046875
  // p = 0 + 2 * 0.140625 * 2 + 0.15625 * 4 + 2 * (-0.046875) * (-1) = 0.5625 + 0.625 + 0.09375 = 1.28125.
  const auto c = channel(P::translation, I::cubic_spline, {0.0f, 2.0f},
                         {{9, 9, 9, 0}, {0, 0, 0, 0}, {2, 0, 0, 0}, {-1, 0, 0, 0}, {4, 1, 0, 0}, {9, 9, 9, 0}});
  expect_near(sample_channel(c, 0.5f), {1.28125f, 0.15625f, 0, 0});
  expect_near(sample_channel(c, 0.0f), {0, 0, 0, 0});  // in-tangents of the first key never matter
  expect_near(sample_channel(c, 2.0f), {4, 1, 0, 0});
  // A malformed channel is refused, not read out of bounds.
  auto bad = c;
  bad.values.pop_back();
  EXPECT_THROW(sample_channel(bad, 1.0f), std::invalid_argument);
  EXPECT_THROW(sample_channel(channel(P::translation, I::linear, {}, {}), 0.0f), std::invalid_argument);
}

TEST(AnimationSampling, ApplyComposesTrsAndWorldFollowsParents) {
  std::vector<Node> nodes(2);
  nodes[1].parent = 0;
  nodes[0].children = {1};
  nodes[1].translation = glm::vec3(0, 1, 0);
  nodes[1].local = glm::translate(glm::mat4(1.0f), nodes[1].translation);
  Animation anim;
  anim.channels.push_back(channel(P::translation, I::linear, {0.0f, 2.0f}, {{0, 0, 0, 0}, {10, 0, 0, 0}}));
  anim.channels.push_back(channel(P::scale, I::step, {0.0f}, {{2, 2, 2, 0}}));
  std::vector<bool> changed;
  apply_animation(anim, 1.0f, nodes, changed);
  ASSERT_EQ(changed.size(), 2u);
  EXPECT_TRUE(changed[0]);
  EXPECT_FALSE(changed[1]);
  const std::vector<glm::mat4> world = node_world_transforms(nodes);
  // Child at parent-local (0,1,0): world = T(5,0,0) S(2) (0,1,0) = (5, 2, 0).
  const glm::vec3 p(world[1] * glm::vec4(0, 0, 0, 1));
  EXPECT_NEAR(p.x, 5.0f, 1e-5f);
  EXPECT_NEAR(p.y, 2.0f, 1e-5f);
  EXPECT_NEAR(p.z, 0.0f, 1e-5f);
}

TEST(SceneAnimator, RigidMotionRebuildsOnlyTheTlas) {
  const Scene s = make_builtin("dynamic?size=6000&seed=2");
  Tlas tlas(s);
  const std::size_t grass = static_cast<std::size_t>(tlas.blas_of_mesh(s.deformers[0].mesh));
  AnimatorOptions ao;
  ao.rebuild_ratio = 0.0;  // always refit
  SceneAnimator anim(s, tlas, ao);
  const FrameStats f = anim.step(0.7f);
  EXPECT_TRUE(f.tlas_rebuilt);
  EXPECT_GT(f.moved_instances, 100u);
  EXPECT_EQ(f.refits, 1u);  // the grass only: the boxes' BLAS is never touched
  EXPECT_EQ(f.rebuilds, 0u);
  EXPECT_GT(f.sah_refit, 0.0);
  EXPECT_GT(f.sah_rebuilt, 0.0);
  // Instance transforms equal the sampled node TRS.
  Scene moved = s;
  std::vector<bool> changed;
  for (const Animation& a : moved.animations) apply_animation(a, 0.7f, moved.nodes, changed);
  const std::vector<glm::mat4> world = node_world_transforms(moved.nodes);
  for (std::size_t i = 0; i < s.instances.size(); ++i)
    ASSERT_EQ(anim.instance_transforms()[i], world[s.instances[i].node]) << i;
  // Queries equal a fresh two-level build of the moved scene (same BLAS vertices).
  for (std::size_t i = 0; i < moved.instances.size(); ++i)
    moved.instances[i].transform = world[moved.instances[i].node];
  const std::vector<Triangle> grass_now = deformed_triangles(s.meshes[s.deformers[0].mesh], s.deformers[0], 0.7f);
  Tlas fresh(moved);
  fresh.rebuild_blas(grass, grass_now);
  const Camera cam = s.cameras.front();
  std::size_t differ = 0, hits = 0;
  for (int y = 0; y < 60; ++y)
    for (int x = 0; x < 80; ++x) {
      const Ray r = primary_ray(cam, x, y, 80, 60);
      const Hit a = tlas.closest_hit(r, QueryOptions{});
      const Hit b = fresh.closest_hit(r, QueryOptions{});
      hits += a.valid();
      differ += a.valid() != b.valid() || (a.valid() && a.t != b.t);
    }
  EXPECT_EQ(differ, 0u);
  EXPECT_GT(hits, 1000u);
}

TEST(SceneAnimator, RebuildFiresAboveTheRatioOnly) {
  const Scene s = make_builtin("dynamic?size=6000&seed=2");
  Tlas never(s), always(s);
  AnimatorOptions no;
  no.rebuild_ratio = 1e9;
  AnimatorOptions yes;
  yes.rebuild_ratio = 1.0 + 1e-12;  // any degradation at all
  SceneAnimator a(s, never, no), b(s, always, yes);
  std::uint32_t rebuilt_never = 0, rebuilt_always = 0;
  for (int f = 0; f < 6; ++f) {
    rebuilt_never += a.step(0.3f * f).rebuilds;
    const FrameStats fb = b.step(0.3f * f);
    rebuilt_always += fb.rebuilds;
    EXPECT_EQ(fb.rebuilds, fb.sah_refit > (1.0 + 1e-12) * fb.sah_rebuilt ? 1u : 0u);
  }
  EXPECT_EQ(rebuilt_never, 0u);
  EXPECT_GT(rebuilt_always, 0u);
}

// ---------------------------------------------------------------------------
// Effects by scene
// ---------------------------------------------------------------------------

TEST(Effects, StaticSceneWithoutLightsTracesNoShadowRaysAndRefitsNothing) {
  Scene s = make_builtin("teapot?size=2000");
  s.lights.clear();
  const SceneEffects fx = decide_effects(s);
  EXPECT_FALSE(fx.shadow_rays.on);
  EXPECT_FALSE(fx.per_frame_updates.on);
  EXPECT_FALSE(fx.two_level.on);
  EXPECT_FALSE(fx.textures.on);
  EXPECT_EQ(fx.structure(), "bvh");
  Tlas tlas(s);
  SceneAnimator anim(s, tlas);
  const Bvh bvh(s.triangles);
  for (int f = 0; f < 3; ++f) {
    const FrameCounters c = run_frame(s, fx, bvh, s.cameras.front(), 40, 30, &anim, 0.1f * f);
    EXPECT_EQ(c.primary_rays, 1200u);
    EXPECT_EQ(c.shadow_rays, 0u);
    EXPECT_EQ(c.refits, 0u);
    EXPECT_EQ(c.rebuilds, 0u);
    EXPECT_EQ(c.tlas_rebuilds, 0u);
  }
  // Even forced on, per-frame updates of a static scene touch nothing.
  EffectForces force;
  ASSERT_TRUE(set_force(force, "per-frame-updates"));
  const SceneEffects forced = decide_effects(s, force);
  EXPECT_TRUE(forced.per_frame_updates.on);
  EXPECT_TRUE(forced.per_frame_updates.forced);
  const FrameCounters c = run_frame(s, forced, bvh, s.cameras.front(), 10, 10, &anim, 0.5f);
  EXPECT_EQ(c.refits, 0u);
  EXPECT_EQ(c.tlas_rebuilds, 0u);
}

TEST(Effects, ALightTurnsShadowRaysOn) {
  Scene s = make_builtin("teapot?size=2000");
  s.lights.clear();
  const Bvh bvh(s.triangles);
  Light sun;
  sun.kind = Light::Kind::directional;
  sun.direction = glm::normalize(glm::vec3(-0.3f, -1.0f, -0.2f));
  s.lights.push_back(sun);
  const SceneEffects fx = decide_effects(s);
  EXPECT_TRUE(fx.shadow_rays.on);
  EXPECT_FALSE(fx.shadow_rays.forced);
  EXPECT_NE(fx.shadow_rays.reason.find("1 light"), std::string::npos);
  const FrameCounters c = run_frame(s, fx, bvh, s.cameras.front(), 40, 30, nullptr, 0.0f);
  EXPECT_GT(c.shadow_rays, 0u);
  EXPECT_LT(c.shadow_rays, c.primary_rays);  // one per primary hit, and some rays miss
  // Without lights and not forced: none. Forced on a scene without lights:
  // they go to one synthetic light above the scene.
  s.lights.clear();
  EXPECT_EQ(run_frame(s, decide_effects(s), bvh, s.cameras.front(), 10, 10, nullptr, 0.0f).shadow_rays, 0u);
  EffectForces f;
  f.shadow_rays = true;
  const SceneEffects forced = decide_effects(s, f);
  EXPECT_TRUE(forced.shadow_rays.forced);
  const std::vector<Light> synthetic = shadow_lights(s, forced.shadow_rays.on);
  ASSERT_EQ(synthetic.size(), 1u);
  EXPECT_EQ(synthetic[0].name, "synthetic");
  EXPECT_GT(synthetic[0].position.y, s.bounds().hi.y);
  const FrameCounters fc = run_frame(s, forced, bvh, s.cameras.front(), 10, 10, nullptr, 0.0f);
  EXPECT_GT(fc.shadow_rays, 0u);
  EXPECT_LE(fc.shadow_rays, fc.primary_rays);
}

TEST(Effects, InstancedSceneBuildsEachUniqueMeshOnce) {
  const Scene s = make_builtin("forest?size=20000&seed=3");
  const SceneEffects fx = decide_effects(s);
  EXPECT_TRUE(fx.two_level.on);
  EXPECT_EQ(fx.structure(), "tlas");
  const Tlas tlas(s);
  EXPECT_EQ(tlas.blas_count(), s.meshes.size());  // tree and ground, once each
  EXPECT_GT(tlas.instances().size(), 100u);
  EXPECT_LT(tlas.memory_two_level(), tlas.memory_flattened_estimate());
  EXPECT_EQ(fx.two_level.reason.rfind("1 mesh instanced more than once (", 0), 0u) << fx.two_level.reason;
  const SceneEffects island = decide_effects(make_builtin("island?size=1"));
  EXPECT_EQ(island.two_level.reason.find("8 meshes instanced more than once ("), 0u) << island.two_level.reason;
  // Textures are never on and cannot be forced.
  EffectForces f;
  f.textures = true;
  const SceneEffects t = decide_effects(s, f);
  EXPECT_FALSE(t.textures.on);
  EXPECT_NE(t.textures.reason.find("cannot be forced"), std::string::npos);
  EffectForces bad;
  EXPECT_FALSE(set_force(bad, "motion-blur"));
  // The dynamic scene calls for per-frame updates; the text lists every effect.
  const SceneEffects d = decide_effects(make_builtin("dynamic?size=3000"));
  EXPECT_TRUE(d.per_frame_updates.on);
  const std::string text = effects_text(d);
  for (const char* name : {"shadow-rays", "per-frame-updates", "two-level", "textures"})
    EXPECT_NE(text.find(name), std::string::npos) << name;
}
}  // namespace unity_test_animation

namespace unity_test_animation {
namespace {

/// One triangle mesh placed by node 0; node 1 empty; node 2 holds a camera; an instance on node 0.
Scene one_placed_mesh() {
  Scene s;
  Mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  m.indices = {{0, 1, 2}};
  s.meshes.push_back(m);
  s.nodes.resize(3);
  s.nodes[0].mesh = 0;
  s.nodes[0].translation = {2, 0, 0};
  s.nodes[2].camera = 0;
  Instance inst;
  inst.mesh = 0;
  inst.node = 0;
  s.instances.push_back(inst);
  return s;
}

Scene with_channel(Scene s, int node, AnimationChannel c) {
  c.node = node;
  s.animations.push_back({"a", {c}});
  return s;
}

}  // namespace

// "No refit without motion": a channel counts only where it moves geometry.
TEST(Effects, AnimationThatMovesNoGeometryCallsForNoUpdates) {
  const Scene s = one_placed_mesh();
  const auto moves = [](const Scene& sc) { return decide_effects(sc).per_frame_updates.on; };
  const AnimationChannel varying = channel(P::translation, I::linear, {0, 1}, {{0, 0, 0, 0}, {0, 1, 0, 0}});
  EXPECT_FALSE(moves(with_channel(s, 1, varying))) << "an empty node";
  EXPECT_FALSE(moves(with_channel(s, 2, varying))) << "a camera's node";
  EXPECT_FALSE(moves(with_channel(s, 7, varying))) << "a node outside the scene";
  EXPECT_TRUE(moves(with_channel(s, 0, varying)));
  // Constant keys: at the node's own translation, nothing moves; elsewhere it moves once (frame 0).
  EXPECT_FALSE(moves(with_channel(s, 0, channel(P::translation, I::linear, {0, 1}, {{2, 0, 0, 0}, {2, 0, 0, 0}}))));
  EXPECT_FALSE(moves(with_channel(s, 0, channel(P::translation, I::step, {0}, {{2, 0, 0, 0}}))));
  EXPECT_TRUE(moves(with_channel(s, 0, channel(P::translation, I::step, {0}, {{3, 0, 0, 0}}))));
  // A cubic spline whose values hold but whose tangents bend moves between its keys.
  const glm::vec4 z(0.0f), at(2, 0, 0, 0), bend(0, 1, 0, 0);
  EXPECT_FALSE(moves(with_channel(s, 0, channel(P::translation, I::cubic_spline, {0, 1}, {z, at, z, z, at, z}))));
  EXPECT_TRUE(moves(with_channel(s, 0, channel(P::translation, I::cubic_spline, {0, 1}, {z, at, bend, z, at, z}))));
  // A parent of the placed node moves it.
  Scene parented = s;
  parented.nodes[1].children = {0};
  parented.nodes[0].parent = 1;
  EXPECT_TRUE(moves(with_channel(parented, 1, varying)));
  // Morph weights: held at the mesh's default weights, no shape changes.
  Scene morph = s;
  morph.meshes[0].morph_base = morph.meshes[0].positions;
  morph.meshes[0].morph_deltas = {{{0, 0, 0}, {0, 0, 0}, {1, 1, 0}}};
  morph.meshes[0].morph_weights = {0.5f};
  EXPECT_FALSE(
      moves(with_channel(morph, 0, channel(P::weights, I::linear, {0, 1}, {{0.5f, 0, 0, 0}, {0.5f, 0, 0, 0}}))));
  EXPECT_TRUE(moves(with_channel(morph, 0, channel(P::weights, I::linear, {0, 1}, {{0.5f, 0, 0, 0}, {1, 0, 0, 0}}))));
  const SceneEffects off = decide_effects(with_channel(s, 2, varying));
  EXPECT_NE(off.per_frame_updates.reason.find("1 animation channel but none moves geometry"), std::string::npos)
      << off.per_frame_updates.reason;
}

// "No shadow rays without lights": a light of intensity (or colour) 0 lights nothing.
TEST(Effects, ALightThatGivesNoLightCastsNoShadow) {
  Scene s = one_placed_mesh();
  Light dark;
  dark.intensity = 0.0f;
  s.lights.push_back(dark);
  SceneEffects fx = decide_effects(s);
  EXPECT_FALSE(fx.shadow_rays.on);
  EXPECT_NE(fx.shadow_rays.reason.find("none gives light"), std::string::npos) << fx.shadow_rays.reason;
  Light lit;
  lit.position = {0, 5, 0};
  s.lights.push_back(lit);
  fx = decide_effects(s);
  EXPECT_TRUE(fx.shadow_rays.on);
  EXPECT_NE(fx.shadow_rays.reason.find("1 light: one any-hit ray"), std::string::npos) << fx.shadow_rays.reason;
  const std::vector<Light> aimed = shadow_lights(s, true);
  ASSERT_EQ(aimed.size(), 1u);
  EXPECT_EQ(aimed[0].position, lit.position);
}

// "No two-level structure without instancing": a mesh without triangles placed twice instances
// nothing, nor does one whose every triangle the flattening drops (a NaN vertex in each).
TEST(Effects, AMeshWithoutTrianglesPlacedTwiceIsNoInstancing) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  Mesh all_nan;
  all_nan.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {nan, 0, 0}};
  all_nan.indices = {{0, 1, 3}, {3, 2, 1}};
  for (const Mesh& placed : {Mesh{} /* points or lines only */, all_nan}) {
    Scene s = one_placed_mesh();
    s.meshes.push_back(placed);
    for (std::uint32_t node : {1u, 2u}) {
      Instance inst;
      inst.mesh = 1;
      inst.node = node;
      s.instances.push_back(inst);
    }
    s.flatten();
    EXPECT_FALSE(s.has_instancing()) << placed.indices.size() << " triangles";
    EXPECT_FALSE(decide_effects(s).two_level.on);
    // One finite triangle is enough for instancing.
    s.meshes[1].indices.push_back({0, 1, 2});
    s.meshes[1].positions.resize(std::max<std::size_t>(s.meshes[1].positions.size(), 3));
    s.flatten();
    EXPECT_TRUE(s.has_instancing());
  }
}

// The synthetic light stands on the default camera's side: a scene camera behind the scene (-z)
// gets it there, so the shadow rays from what the camera sees are not all blocked by the surface.
TEST(Effects, TheSyntheticLightStandsOnTheCamerasSide) {
  Scene s = one_placed_mesh();
  s.flatten();
  const glm::vec3 c = s.bounds().center();
  EXPECT_GT(synthetic_light(s).position.z, c.z) << "no camera: the framing view's side (+x, +z)";
  Camera behind;
  behind.position = c + glm::vec3(0, 0, -4);
  s.cameras.push_back(behind);
  EXPECT_LT(synthetic_light(s).position.z, c.z);
  EXPECT_NEAR(synthetic_light(s).position.x, c.x, 1e-5f);
}

}  // namespace unity_test_animation
