// The GL camera matrices agree with the CPU primary-ray convention: a world
// point projects to the pixel whose primary ray passes through it.
#include "gl_fixture.h"

#include "core/query/camera.h"
#include "ui/render/camera_view.h"

#include <cmath>
#include <random>

namespace accelviz::test {
namespace {

// The CPU convention written out independently: pixel (x, y) centre at
// (x + 0.5, y + 0.5), row 0 at the top, image plane at unit distance
// spanning tan(yfov/2) vertically and aspect times that horizontally.
glm::vec3 cpu_ray_direction(const Camera& cam, float px, float py, int w, int h) {
  const float aspect = cam.aspect > 0.0f ? cam.aspect : static_cast<float>(w) / static_cast<float>(h);
  const float tan_half = std::tan(cam.yfov * 0.5f);
  const glm::vec3 f = glm::normalize(cam.forward);
  const glm::vec3 right = glm::normalize(glm::cross(f, cam.up));
  const glm::vec3 up = glm::cross(right, f);
  const float sx = (2.0f * px / static_cast<float>(w) - 1.0f) * tan_half * aspect;
  const float sy = (1.0f - 2.0f * py / static_cast<float>(h)) * tan_half;
  return glm::normalize(f + sx * right + sy * up);
}

struct Case {
  Camera camera;
  int width, height;
};

std::vector<Case> cases() {
  Camera tilted = look_from({3.0f, 2.0f, 5.0f}, {0.2f, -0.1f, 0.0f}, 0.9f);
  Camera wide = look_from({-4.0f, 1.0f, -2.0f}, {0.0f, 0.0f, 0.0f}, 1.4f);
  Camera fixed_aspect = look_from({0.0f, 5.0f, 0.1f}, {0.0f, 0.0f, 0.0f}, 0.6f);
  fixed_aspect.aspect = 2.0f;  // stretched on purpose: the camera's own aspect wins
  return {{Camera{}, 128, 96}, {tilted, 256, 192}, {wide, 100, 300}, {fixed_aspect, 160, 160}};
}

TEST(CameraView, ProjectedPixelIsThePixelWhoseRayPassesThroughThePoint) {
  std::mt19937 rng(7);
  for (const Case& c : cases()) {
    const CameraMatrices m = camera_matrices(c.camera, c.width, c.height, {0.1f, 100.0f});
    std::uniform_int_distribution<int> px(0, c.width - 1), py(0, c.height - 1);
    std::uniform_real_distribution<float> depth(0.5f, 20.0f);
    for (int i = 0; i < 200; ++i) {
      const int x = px(rng), y = py(rng);
      // A point on the ray through pixel (x, y)'s centre...
      const glm::vec3 p =
          c.camera.position + depth(rng) * cpu_ray_direction(c.camera, x + 0.5f, y + 0.5f, c.width, c.height);
      // ...projects back onto that centre through the GL matrices.
      const std::optional<glm::vec2> q = project_to_pixel(m, p);
      ASSERT_TRUE(q.has_value());
      EXPECT_NEAR(q->x, x + 0.5f, 1e-3f) << "pixel " << x << "," << y << " of " << c.width << "x" << c.height;
      EXPECT_NEAR(q->y, y + 0.5f, 1e-3f) << "pixel " << x << "," << y << " of " << c.width << "x" << c.height;
      EXPECT_EQ(static_cast<int>(std::floor(q->x)), x);
      EXPECT_EQ(static_cast<int>(std::floor(q->y)), y);
    }
  }
}

TEST(CameraView, AgreesWithCorePrimaryRays) {
  // The same check against the tracer's own primary_ray (core/query/camera.h).
  for (const Case& c : cases()) {
    const CameraMatrices m = camera_matrices(c.camera, c.width, c.height, {0.1f, 100.0f});
    for (int y = 0; y < c.height; y += 7) {
      for (int x = 0; x < c.width; x += 5) {
        const Ray r = primary_ray(c.camera, x, y, c.width, c.height);
        const std::optional<glm::vec2> q = project_to_pixel(m, r.at(3.0f));
        ASSERT_TRUE(q.has_value());
        EXPECT_NEAR(q->x, x + 0.5f, 1e-3f);
        EXPECT_NEAR(q->y, y + 0.5f, 1e-3f);
      }
    }
  }
}

TEST(CameraView, TopRowIsUpAndLeftColumnIsLeft) {
  const Camera cam;  // at +5 z looking down -z, +y up
  const CameraMatrices m = camera_matrices(cam, 128, 96, {0.1f, 100.0f});
  const glm::vec2 above = *project_to_pixel(m, {0.0f, 1.0f, 0.0f});
  const glm::vec2 left = *project_to_pixel(m, {-1.0f, 0.0f, 0.0f});
  EXPECT_LT(above.y, 48.0f);
  EXPECT_NEAR(above.x, 64.0f, 1e-3f);
  EXPECT_LT(left.x, 64.0f);
  EXPECT_NEAR(left.y, 48.0f, 1e-3f);
}

TEST(CameraView, PointsBehindTheEyeDoNotProject) {
  const CameraMatrices m = camera_matrices(Camera{}, 64, 64, {0.1f, 100.0f});
  EXPECT_FALSE(project_to_pixel(m, {0.0f, 0.0f, 6.0f}).has_value());
}

TEST(CameraView, FittedClipPlanesEncloseTheBounds) {
  const Camera cam = look_from({0.0f, 0.0f, 10.0f}, {0.0f, 0.0f, 0.0f});
  const Aabb box{{-1.0f, -1.0f, -1.0f}, {1.0f, 1.0f, 1.0f}};
  const ClipPlanes clip = fit_clip_planes(cam, box);
  EXPECT_GT(clip.z_near, 0.0f);
  EXPECT_LE(clip.z_near, 9.0f);
  EXPECT_GE(clip.z_far, 11.0f);
  // From inside the box the near plane stays positive and small.
  const ClipPlanes inside = fit_clip_planes(look_from({0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, -1.0f}), box);
  EXPECT_GT(inside.z_near, 0.0f);
  EXPECT_LT(inside.z_near, 0.01f);
  EXPECT_GE(inside.z_far, 1.0f);
  // An empty scene gets usable defaults.
  const ClipPlanes empty = fit_clip_planes(cam, Aabb::empty());
  EXPECT_LT(empty.z_near, empty.z_far);
}

}  // namespace
}  // namespace accelviz::test
