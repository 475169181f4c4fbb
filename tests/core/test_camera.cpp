#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "core/accel/brute_force.h"
#include "core/query/batch.h"
#include "core/query/camera.h"
#include "core/query/ray_sets.h"
#include "core/scene/effects.h"
#include "tests/core/spatial_test_scenes.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_camera {

using namespace accelviz;

namespace {

constexpr float kPi = 3.14159265358979f;

float angle_between(const glm::vec3& a, const glm::vec3& b) {
  return std::acos(std::clamp(glm::dot(glm::normalize(a), glm::normalize(b)), -1.0f, 1.0f));
}

Camera test_camera() {
  return look_at({1.0f, 2.0f, 3.0f}, {-2.0f, 0.5f, -1.0f}, 50.0f * kPi / 180.0f);
}

}  // namespace

TEST(Camera, LookAtIsOrthonormal) {
  const Camera cam = test_camera();
  EXPECT_NEAR(glm::length(cam.forward), 1.0f, 1e-6f);
  EXPECT_NEAR(glm::length(cam.up), 1.0f, 1e-6f);
  EXPECT_NEAR(glm::dot(cam.forward, cam.up), 0.0f, 1e-6f);
  EXPECT_GT(cam.up.y, 0.0f);  // world up stays up
}

TEST(Camera, CentrePixelRayAlongForward) {
  const Camera cam = test_camera();
  // Odd size: pixel (W/2, H/2) is exactly the image centre.
  const Ray r = primary_ray(cam, 50, 30, 101, 61);
  EXPECT_EQ(r.origin, cam.position);
  EXPECT_NEAR(angle_between(r.direction, cam.forward), 0.0f, 1e-3f);
  EXPECT_NEAR(glm::length(r.direction), 1.0f, 1e-6f);
  EXPECT_EQ(r.tmin, 0.0f);
  EXPECT_TRUE(std::isinf(r.tmax));
}

TEST(Camera, ImageEdgesAtHalfFov) {
  const Camera cam = test_camera();
  const float aspect = 2.0f;
  const float half_v = 0.5f * cam.yfov;
  const float half_h = std::atan(std::tan(half_v) * aspect);
  // Top and bottom edge centres lie at ±yfov/2 from the view axis; the top one is up.
  const Ray top = camera_ray(cam, 0.5f, 0.0f, aspect);
  const Ray bottom = camera_ray(cam, 0.5f, 1.0f, aspect);
  EXPECT_NEAR(angle_between(top.direction, cam.forward), half_v, 1e-5f);
  EXPECT_NEAR(angle_between(bottom.direction, cam.forward), half_v, 1e-5f);
  EXPECT_GT(glm::dot(top.direction, cam.up), 0.0f);
  EXPECT_LT(glm::dot(bottom.direction, cam.up), 0.0f);
  // Left and right edges at the horizontal half-angle; right is forward × up.
  const glm::vec3 right = glm::cross(cam.forward, cam.up);
  const Ray left_ray = camera_ray(cam, 0.0f, 0.5f, aspect);
  const Ray right_ray = camera_ray(cam, 1.0f, 0.5f, aspect);
  EXPECT_NEAR(angle_between(left_ray.direction, cam.forward), half_h, 1e-5f);
  EXPECT_NEAR(angle_between(right_ray.direction, cam.forward), half_h, 1e-5f);
  EXPECT_LT(glm::dot(left_ray.direction, right), 0.0f);
  EXPECT_GT(glm::dot(right_ray.direction, right), 0.0f);
  // A corner: both offsets at once (tan of the offsets add in the image plane).
  const Ray corner = camera_ray(cam, 0.0f, 0.0f, aspect);
  const float expected = std::atan(std::hypot(std::tan(half_v), std::tan(half_h)));
  EXPECT_NEAR(angle_between(corner.direction, cam.forward), expected, 1e-5f);
}

TEST(Camera, PixelZeroIsTopLeft) {
  const Camera cam = look_at({0, 0, 5}, {0, 0, 0}, 1.0f);
  const Ray r = primary_ray(cam, 0, 0, 64, 48);
  EXPECT_LT(r.direction.x, 0.0f);  // left
  EXPECT_GT(r.direction.y, 0.0f);  // up
}

TEST(Camera, ExplicitAspectOverridesImage) {
  Camera cam = look_at({0, 0, 5}, {0, 0, 0}, 1.0f);
  EXPECT_FLOAT_EQ(camera_aspect(cam, 200, 100), 2.0f);
  cam.aspect = 1.0f;
  EXPECT_FLOAT_EQ(camera_aspect(cam, 200, 100), 1.0f);
}

// Bounds near the float range overflow the framing camera's distance: a
// range_error that says so (the CLI named it a --camera usage error before).
TEST(Camera, FrameBoundsOfHugeBoundsIsARangeError) {
  const Aabb huge{{-3e38f, -3e38f, 0.0f}, {3e38f, 3e38f, 3e38f}};
  try {
    frame_bounds(huge, 1.0f);
    ADD_FAILURE() << "framed bounds of 3e38";
  } catch (const std::range_error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot frame the scene: a camera that sees its bounds (-3e+38, -3e+38, 0)"),
              std::string::npos)
        << e.what();
  }
  // Large, but their cameras fit (at 1e20 the extent's squared length
  // overflows float: it said "beyond the float range" for a camera at ~5e20).
  for (const float s : {1e18f, 1e20f, 1e36f}) {
    const Camera cam = frame_bounds(Aabb{glm::vec3(-s), glm::vec3(s)}, 1.0f);
    EXPECT_TRUE(std::isfinite(cam.position.x) && std::isfinite(cam.position.y) && std::isfinite(cam.position.z)) << s;
    EXPECT_GT(glm::length(glm::dvec3(cam.position)), 1.7 * s) << s;  // outside the bounding sphere
  }
}

TEST(Camera, FrameBoundsContainsBoundingSphere) {
  const Aabb box{{-3.0f, 1.0f, 2.0f}, {5.0f, 2.0f, 4.0f}};
  for (float aspect : {0.5f, 1.0f, 4.0f / 3.0f, 3.0f}) {
    const Camera cam = frame_bounds(box, aspect);
    const glm::vec3 c = box.center();
    const float r = 0.5f * glm::length(box.extent());
    // Looks at the centre.
    EXPECT_NEAR(angle_between(c - cam.position, cam.forward), 0.0f, 1e-4f);
    // The sphere's angular radius fits inside both half-angles (tight on one of them).
    const float dist = glm::length(c - cam.position);
    EXPECT_GT(dist, r);
    const float sphere_half = std::asin(r / dist);
    const float half_v = 0.5f * cam.yfov;
    const float half_h = std::atan(std::tan(half_v) * aspect);
    EXPECT_LE(sphere_half, half_v + 1e-5f);
    EXPECT_LE(sphere_half, half_h + 1e-5f);
    EXPECT_NEAR(sphere_half, std::min(half_v, half_h), 1e-4f);
    // Every box corner projects inside the image.
    for (int k = 0; k < 8; ++k) {
      const glm::vec3 p((k & 1) ? box.hi.x : box.lo.x, (k & 2) ? box.hi.y : box.lo.y, (k & 4) ? box.hi.z : box.lo.z);
      const glm::vec3 d = p - cam.position;
      const glm::vec3 right = glm::cross(cam.forward, cam.up);
      const float z = glm::dot(d, cam.forward);
      ASSERT_GT(z, 0.0f);
      EXPECT_LE(std::abs(glm::dot(d, cam.up) / z), std::tan(half_v) + 1e-5f);
      EXPECT_LE(std::abs(glm::dot(d, right) / z), std::tan(half_h) + 1e-5f);
    }
  }
}

TEST(Camera, FrameBoundsOfEmptyBoxIsDefault) {
  const Camera cam = frame_bounds(Aabb::empty(), 1.5f);
  EXPECT_EQ(cam.position, Camera{}.position);
}

TEST(Camera, SpecEyeTargetFov) {
  Scene scene;
  const Camera cam = camera_from_spec("0,0,10,0,0,0,30", scene, 1.0f);
  EXPECT_EQ(cam.position, glm::vec3(0, 0, 10));
  EXPECT_NEAR(cam.forward.z, -1.0f, 1e-6f);
  EXPECT_NEAR(cam.yfov, 30.0f * kPi / 180.0f, 1e-6f);
  const Camera def = camera_from_spec("1, 2, 3, 0, 0, 0", scene, 1.0f);
  EXPECT_NEAR(def.yfov, 45.0f * kPi / 180.0f, 1e-6f);
}

TEST(Camera, SpecDefaultUsesSceneCameraThenBounds) {
  Scene scene;
  scene.triangles.push_back({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  const Camera framed = camera_from_spec("", scene, 1.0f);
  EXPECT_EQ(framed.name, "framed");
  Camera c;
  c.name = "first";
  c.position = {7, 7, 7};
  scene.cameras.push_back(c);
  c.name = "second";
  scene.cameras.push_back(c);
  EXPECT_EQ(camera_from_spec("", scene, 1.0f).name, "first");
  EXPECT_EQ(camera_from_spec("gltf:1", scene, 1.0f).name, "second");
}

TEST(Camera, BadSpecsThrowOneLine) {
  Scene scene;
  for (const char* bad : {"1,2,3", "1,2,3,4,5,x", "1,2,3,1,2,3", "0,0,1,0,0,0,0", "0,0,1,0,0,0,180", "gltf:", "gltf:0",
                          "gltf:-1", "nan,0,0,0,0,0", "1,2,3,4,5,6,7,8"}) {
    try {
      camera_from_spec(bad, scene, 1.0f);
      ADD_FAILURE() << "accepted " << bad;
    } catch (const std::invalid_argument& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find(bad), std::string::npos) << msg;
      EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    }
  }
}

// ---- ray sets built on the camera (core/query/ray_sets) ----

namespace {

/// A floor and a wall facing the camera, so primary rays hit two orientations.
std::vector<Triangle> floor_and_wall() {
  return {{{-5, 0, -5}, {5, 0, -5}, {-5, 0, 5}},
          {{5, 0, -5}, {5, 0, 5}, {-5, 0, 5}},
          {{-5, 0, -3}, {5, 0, -3}, {-5, 6, -3}},
          {{5, 0, -3}, {5, 6, -3}, {-5, 6, -3}}};
}

/// floor_and_wall seen from above and in front: its triangles, a w x h image's primary rays and their hits.
struct FloorAndWallView {
  std::vector<Triangle> tris = floor_and_wall();
  std::vector<Ray> primary;
  std::vector<Hit> hits;
};

FloorAndWallView floor_and_wall_view(int w, int h, unsigned threads) {
  FloorAndWallView v;
  const BruteForce accel(v.tris);
  v.primary = primary_rays(look_at({1, 3, 9}, {0, 1, -3}, 0.9f), w, h);
  v.hits.resize(v.primary.size());
  trace_closest(accel, v.primary, v.hits, {}, threads);
  return v;
}

}  // namespace

TEST(RaySets, PrimaryRaysAreRowMajorFromTopLeft) {
  const Camera cam = look_at({0, 2, 8}, {0, 1, 0}, 0.8f);
  const std::vector<Ray> rays = primary_rays(cam, 7, 5);
  ASSERT_EQ(rays.size(), 35u);
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 7; ++x) EXPECT_EQ(rays[y * 7 + x].direction, primary_ray(cam, x, y, 7, 5).direction);
}

TEST(RaySets, DiffuseRaysLeaveTheSurfaceOnTheCameraSideAndAreSeeded) {
  const auto [tris, primary, hits] = floor_and_wall_view(32, 24, 2u);
  const BruteForce accel(tris);
  const std::size_t hit_count = std::count_if(hits.begin(), hits.end(), [](const Hit& h) { return h.valid(); });
  ASSERT_GT(hit_count, 100u);

  const std::vector<Ray> a = diffuse_rays(tris, primary, hits, 42);
  const std::vector<Ray> b = diffuse_rays(tris, primary, hits, 42);
  const std::vector<Ray> c = diffuse_rays(tris, primary, hits, 43);
  ASSERT_EQ(a.size(), hit_count);
  double mean_cos = 0.0;
  std::size_t k = 0;
  for (std::size_t i = 0; i < hits.size(); ++i) {
    if (!hits[i].valid()) continue;
    glm::vec3 n = hits[i].ng;
    if (glm::dot(n, primary[i].direction) > 0.0f) n = -n;
    EXPECT_GT(glm::dot(a[k].direction, n), 0.0f);  // into the hemisphere the camera sees
    EXPECT_NEAR(glm::length(a[k].direction), 1.0f, 1e-5f);
    EXPECT_EQ(a[k].direction, b[k].direction);  // same seed, same rays
    // The origin is on the camera side of the surface and leaves it: nothing at t = 0.
    EXPECT_FALSE(accel.closest_hit(Ray(a[k].origin, a[k].direction, 0.0f, 1e-3f), {}).valid());
    mean_cos += glm::dot(a[k].direction, n);
    ++k;
  }
  // Cosine-weighted: E[cos θ] = 2/3.
  EXPECT_NEAR(mean_cos / static_cast<double>(k), 2.0 / 3.0, 0.03);
  std::size_t same = 0;
  for (std::size_t i = 0; i < a.size(); ++i) same += a[i].direction == c[i].direction;
  EXPECT_LT(same, a.size() / 100);  // another seed, other directions
}

// A closed cube and the same cube scaled by 2^-17 (about 7.6e-6; exact in
// float, so the camera and its rays scale exactly): the secondary rays leave
// their surfaces alike. The offset's absolute floor of 1/65536 put the tiny
// cube's origins beyond it: no shadow ray was made, and bounces left from
// outside the cube.
TEST(RaySets, SecondaryRaysOfATinySceneAreThoseOfAUnitScene) {
  const float tiny = std::ldexp(1.0f, -17);
  std::size_t shadow_count[2] = {}, occluded[2] = {}, bounces_hit[2] = {}, own_hits[2] = {};
  for (int k = 0; k < 2; ++k) {
    std::vector<Triangle> tris = test_scenes::subdivided_cube(glm::vec3(-1.0f), 2.0f, 4);
    if (k == 1)
      for (Triangle& t : tris) t = {t.v0 * tiny, t.v1 * tiny, t.v2 * tiny};
    Aabb b;
    for (const Triangle& t : tris) b.extend(t.bounds());
    const BruteForce accel(tris);
    const std::vector<Ray> primary = primary_rays(frame_bounds(b, 4.0f / 3.0f), 32, 24);
    std::vector<Hit> hits(primary.size());
    trace_closest(accel, primary, hits, {}, 1u);
    const Light light = synthetic_light(b);
    const std::vector<Ray> shadows = shadow_rays(tris, primary, hits, std::span<const Light>(&light, 1));
    shadow_count[k] = shadows.size();
    for (const Ray& r : shadows) occluded[k] += accel.any_hit(r, {});
    const std::vector<Ray> bounces = diffuse_rays(tris, primary, hits, 3);
    for (std::size_t i = 0, j = 0; i < hits.size(); ++i) {
      if (!hits[i].valid()) continue;
      const Hit h = accel.closest_hit(bounces[j++], {});
      bounces_hit[k] += h.valid();  // the bounces leave the cube's outside: most miss
      own_hits[k] += h.valid() && h.prim == hits[i].prim;
    }
  }
  EXPECT_GT(shadow_count[0], 20u);
  EXPECT_EQ(shadow_count[1], shadow_count[0]);
  EXPECT_EQ(occluded[1], occluded[0]);
  EXPECT_EQ(own_hits[0], 0u);
  EXPECT_EQ(own_hits[1], 0u);
  EXPECT_EQ(bounces_hit[1], bounces_hit[0]);
}

TEST(RaySets, ShadowRaysGoToLightsInFrontOfTheSurface) {
  const auto [tris, primary, hits] = floor_and_wall_view(16, 12, 1u);
  Light point;
  point.position = {0, 4, 0};  // above the floor, in front of the wall
  Light below;
  below.position = {0, -4, 0};  // under the floor: lights nothing the camera sees on it
  Light sun;
  sun.kind = Light::Kind::directional;
  sun.direction = glm::normalize(glm::vec3(0.2f, -1.0f, -0.3f));
  const std::vector<Light> lights = {point, below, sun};
  const std::vector<Ray> rays = shadow_rays(tris, primary, hits, lights);
  // One ray per (hit, light) pair whose light lies on the side the camera sees.
  std::size_t expected = 0;
  for (std::size_t i = 0; i < hits.size(); ++i) {
    if (!hits[i].valid()) continue;
    glm::vec3 n = hits[i].ng;
    if (glm::dot(n, primary[i].direction) > 0.0f) n = -n;
    const glm::vec3 p = primary[i].at(hits[i].t);
    expected += glm::dot(point.position - p, n) > 0.0f;
    expected += glm::dot(below.position - p, n) > 0.0f;
    expected += glm::dot(-sun.direction, n) > 0.0f;
  }
  EXPECT_EQ(rays.size(), expected);
  std::size_t to_below = 0;
  for (const Ray& r : rays) {
    if (!std::isfinite(r.tmax)) {
      EXPECT_NEAR(glm::dot(r.direction, -sun.direction), 1.0f, 1e-5f);
      continue;
    }
    // tmax stops 1e-4 of the distance short of the light.
    const glm::vec3 end = r.at(r.tmax);
    const bool is_point = glm::distance(end, point.position) < 2e-4f * glm::distance(r.origin, point.position);
    const bool is_below = glm::distance(end, below.position) < 2e-4f * glm::distance(r.origin, below.position);
    EXPECT_TRUE(is_point || is_below);  // ends just short of a positional light
    if (is_below) {
      ++to_below;
      EXPECT_NEAR(r.origin.z, -3.0f, 1e-3f);  // only wall points see the light under the floor
    }
  }
  EXPECT_GT(to_below, 0u);
  const Light synthetic = synthetic_light(Aabb{{-5, 0, -5}, {5, 6, 5}});
  EXPECT_GT(synthetic.position.y, 6.0f);
}

// A light farther than about 1.8e19 squared its distance past float's range: its shadow rays were
// dropped, none at all, as if it lit nothing. Up to float's largest finite distance each lit hit has one.
TEST(RaySets, ShadowRaysReachAVeryFarLight) {
  const auto [tris, primary, hits] = floor_and_wall_view(16, 12, 1u);
  Light near_light, far_light;
  near_light.position = {0.0f, 4.0f, 1.0f};
  far_light.position = glm::normalize(glm::vec3(0.0f, 4.0f, 1.0f)) * 1e38f;
  const std::size_t near = shadow_rays(tris, primary, hits, std::vector<Light>{near_light}).size();
  const std::vector<Ray> far = shadow_rays(tris, primary, hits, std::vector<Light>{far_light});
  EXPECT_GT(near, 0u);
  EXPECT_GE(far.size(), near / 2) << "the far light lights what faces it";
  for (const Ray& r : far) {
    EXPECT_TRUE(std::isfinite(r.tmax));
    EXPECT_GT(r.tmax, 9e37f);
    EXPECT_NEAR(glm::length(r.direction), 1.0f, 1e-5f);
  }
}
}  // namespace unity_test_camera
