// Click to cast: the pixel's ray is core's primary ray, its hit is brute
// force's, its trace is the structure's, shadow rays go to each light, and
// the replay walks the trace in order.
#include <gtest/gtest.h>

#include <cmath>

#include "core/accel/brute_force.h"
#include "core/accel/factory.h"
#include "core/query/camera.h"
#include "core/scene/load.h"
#include "ui/app/ray_inspection.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_app_ray_inspection {

using namespace accelviz;

namespace {

std::shared_ptr<const BuiltStructure> build(Scene scene, const char* name) {
  auto loaded = std::make_shared<LoadedScene>();
  loaded->scene = std::move(scene);
  auto b = std::make_shared<BuiltStructure>();
  b->accel = build_accelerator(name, loaded->scene.triangles, StructureOptions{});
  b->nodes = StructureNodes::of(*b->accel);
  b->scene = loaded;
  return b;
}

}  // namespace

TEST(AppRayInspection, PixelRayHitsWhatBruteForceHits) {
  const Scene scene = load_scene("builtin:teapot?size=1000");
  const BruteForce brute(scene.triangles);
  const Camera cam = look_at({6, 4, 8}, {0, 1.2f, 0}, 40.0f * 3.14159265f / 180.0f);
  for (const char* name : {"bvh", "kdtree", "grid", "octree"}) {
    SCOPED_TRACE(name);
    const auto b = build(scene, name);
    int hits = 0;
    for (int y = 0; y < 48; y += 6)
      for (int x = 0; x < 64; x += 6) {
        const RayInspection r = inspect_pixel(*b, cam, x, y, 64, 48, {});
        const Ray expected = primary_ray(cam, x, y, 64, 48);
        EXPECT_EQ(r.ray.origin, expected.origin);
        EXPECT_EQ(r.ray.direction, expected.direction);
        const Hit h = brute.closest_hit(expected, {});
        EXPECT_EQ(r.hit.valid(), h.valid());
        if (!h.valid()) continue;
        ++hits;
        EXPECT_EQ(r.hit.t, h.t);
        EXPECT_EQ(r.structure, name);
        EXPECT_FALSE(r.trace.steps.empty());
        // The trace and the counters describe the same traversal.
        std::uint32_t entered = 0, tests = 0;
        for (const VisitStep& s : r.trace.steps) {
          entered += s.kind == VisitStep::Kind::node_entered;
          tests += s.kind == VisitStep::Kind::prim_hit || s.kind == VisitStep::Kind::prim_miss;
        }
        EXPECT_GT(entered, 0u);
        EXPECT_EQ(tests, r.stats.prim_tests);
      }
    EXPECT_GT(hits, 10);
  }
}

TEST(AppRayInspection, ShadowRaysGoToEachLightOnTheLitSide) {
  Scene s;
  // A floor at y = 0 (facing up) and a roof at y = 2 over part of it.
  s.triangles = {{{-10, 0, -10}, {10, 0, 10}, {10, 0, -10}},
                 {{-10, 0, -10}, {-10, 0, 10}, {10, 0, 10}},
                 {{-1, 2, -1}, {1, 2, 1}, {1, 2, -1}},
                 {{-1, 2, -1}, {-1, 2, 1}, {1, 2, 1}}};
  Light above;
  above.name = "above";
  above.position = {0, 5, 0};
  Light sun;
  sun.kind = Light::Kind::directional;
  sun.direction = glm::normalize(glm::vec3(-1, -1, 0));  // travels down and to -x
  Light below;
  below.position = {0, -5, 0};  // under the floor: not on the lit side
  s.lights = {above, sun, below};
  const auto b = build(s, "bvh");
  // Looking straight down at the floor under the roof's corner... from below the roof.
  RayInspection like;
  like.ray = Ray({0.2f, 1.0f, 0.3f}, {0.0f, -1.0f, 0.0f});
  const RayInspection r = inspect_ray(*b, like, {});
  ASSERT_TRUE(r.hit.valid());
  EXPECT_NEAR(r.hit.t, 1.0f, 1e-5f);
  ASSERT_EQ(r.shadows.size(), 2u) << "the light under the floor is skipped";
  EXPECT_EQ(r.shadows[0].light, 0u);
  EXPECT_EQ(r.shadows[0].light_name, "above");
  EXPECT_TRUE(r.shadows[0].occluded) << "the roof is in the way";
  EXPECT_LT(r.shadows[0].ray.tmax, glm::length(above.position - r.shadows[0].ray.origin)) << "stops short of the light";
  EXPECT_EQ(r.shadows[1].light, 1u);
  EXPECT_TRUE(std::isinf(r.shadows[1].ray.tmax));
  EXPECT_GT(r.shadows[1].ray.direction.y, 0.0f) << "towards where the sun is";
  EXPECT_GT(r.shadows[1].stats.box_tests, 0u);
  // Out from under the roof the point light is visible.
  like.ray = Ray({5.0f, 1.0f, 5.0f}, {0.0f, -1.0f, 0.0f});
  EXPECT_FALSE(inspect_ray(*b, like, {}).shadows[0].occluded);
  // A miss casts no shadow rays.
  like.ray = Ray({50.0f, 1.0f, 0.0f}, {0.0f, -1.0f, 0.0f});
  const RayInspection miss = inspect_ray(*b, like, {});
  EXPECT_FALSE(miss.hit.valid());
  EXPECT_TRUE(miss.shadows.empty());
}

TEST(AppRayInspection, ReplayWalksTheTraceInOrder) {
  VisitTrace t;
  using Kd = VisitStep::Kind;
  t.steps = {{Kd::node_entered, 0, 1, 9},     {Kd::node_missed, 2, 2, 3},
             {Kd::node_entered, 1, 1, 5},     {Kd::prim_miss, 7, kInfinity, kInfinity},
             {Kd::prim_hit, 4, 3, kInfinity}, {Kd::prim_miss, 7, kInfinity, kInfinity},
             {Kd::node_culled, 5, 6, 8}};
  ReplayState s = replay_upto(t, 0);
  EXPECT_EQ(s.entered, std::vector<std::uint32_t>{0});
  EXPECT_EQ(s.current_node, 0u);
  EXPECT_TRUE(s.tested.empty());
  s = replay_upto(t, 1);
  EXPECT_EQ(s.current_node, 2u) << "a missed node is the current one while it is being tested";
  EXPECT_EQ(s.entered, std::vector<std::uint32_t>{0});
  s = replay_upto(t, 5);
  EXPECT_EQ(s.entered, (std::vector<std::uint32_t>{0, 1}));
  EXPECT_EQ(s.tested, (std::vector<std::uint32_t>{7, 4})) << "each primitive once, in first-test order";
  s = replay_upto(t, 100);
  EXPECT_EQ(s.current_node, 5u);
  // The boxes drawn: a missed node last while it is the current step; at the walk's end the last node
  // entered, not the sibling culled after the hit (it read as the last box visited).
  EXPECT_EQ(replay_box_ids(t, 1), (std::vector<std::uint32_t>{0, 2}));
  EXPECT_EQ(replay_box_ids(t, 5), (std::vector<std::uint32_t>{0, 1}));
  EXPECT_EQ(replay_box_ids(t, 6), (std::vector<std::uint32_t>{0, 1}));
  VisitTrace shorter = t;
  shorter.steps.push_back({Kd::prim_miss, 8, kInfinity, kInfinity});
  EXPECT_EQ(replay_box_ids(shorter, 6), (std::vector<std::uint32_t>{0, 1, 5})) << "a cull stepped to is drawn";
}

TEST(AppRayInspection, JsonListsHitStepsAndShadows) {
  const Scene scene = load_scene("builtin:teapot?size=500");
  const auto b = build(scene, "bvh");
  const Camera cam = camera_from_spec("", scene, 1.0f);
  const RayInspection r = inspect_pixel(*b, cam, 16, 16, 32, 32, {});
  ASSERT_TRUE(r.hit.valid());
  const nlohmann::json j = inspection_json(r, 3);
  EXPECT_EQ(j["pixel"], nlohmann::json::array({16, 16}));
  EXPECT_EQ(j["size"], nlohmann::json::array({32, 32}));
  EXPECT_EQ(j["structure"], "bvh");
  EXPECT_EQ(j["hit"]["prim"], r.hit.prim);
  EXPECT_FLOAT_EQ(j["hit"]["t"].get<float>(), r.hit.t);
  EXPECT_EQ(j["steps"].size(), r.trace.steps.size());
  EXPECT_EQ(j["steps"][0]["kind"], "entered");
  EXPECT_EQ(j["replay_step"], 3);
  EXPECT_EQ(j["stats"]["prim_tests"], r.stats.prim_tests);
  EXPECT_EQ(j["shadows"].size(), r.shadows.size());
  EXPECT_EQ(j["shadows"].size(), scene.lights.size());
  // Infinite t values (primitive steps) are written as null, never as "inf".
  bool saw_null = false;
  for (const auto& s : j["steps"]) saw_null |= s["t_exit"].is_null();
  EXPECT_TRUE(saw_null);
  EXPECT_EQ(j.dump().find("inf"), std::string::npos);
}
}  // namespace unity_test_app_ray_inspection
