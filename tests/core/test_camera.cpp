#include <gtest/gtest.h>

#include "core/query/camera.h"

#include <cmath>

using namespace accelviz;

namespace {

constexpr float kPi = 3.14159265358979f;

float angle_between(const glm::vec3& a, const glm::vec3& b) {
  return std::acos(std::clamp(glm::dot(glm::normalize(a), glm::normalize(b)), -1.0f, 1.0f));
}

Camera test_camera() { return look_at({1.0f, 2.0f, 3.0f}, {-2.0f, 0.5f, -1.0f}, 50.0f * kPi / 180.0f); }

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
  for (const char* bad : {"1,2,3", "1,2,3,4,5,x", "1,2,3,1,2,3", "0,0,1,0,0,0,0", "0,0,1,0,0,0,180", "gltf:",
                          "gltf:0", "gltf:-1", "nan,0,0,0,0,0", "1,2,3,4,5,6,7,8"}) {
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
