// Orbit camera math: the eye on its sphere around the pivot, orbit/pan/zoom
// moves, the pivot pick, framing, conversion from scene cameras, and the
// --camera spec that reproduces a view in `accelviz render`.
#include <gtest/gtest.h>

#include <cmath>

#include "core/query/camera.h"
#include "ui/app/orbit_camera.h"

// Own namespace: this file is compiled together with others (tests/CMakeLists.txt, unity build).
namespace unity_test_app_orbit_camera {

using namespace accelviz;

namespace {

void expect_vec_near(const glm::vec3& a, const glm::vec3& b, float tol, const char* what = "") {
  EXPECT_NEAR(a.x, b.x, tol) << what;
  EXPECT_NEAR(a.y, b.y, tol) << what;
  EXPECT_NEAR(a.z, b.z, tol) << what;
}

OrbitCamera sample() {
  OrbitCamera o;
  o.pivot = {1.0f, 2.0f, -3.0f};
  o.distance = 10.0f;
  o.yaw = 0.7f;
  o.pitch = 0.3f;
  o.yfov = 0.9f;
  return o;
}

Scene box_scene() {
  Scene s;
  s.triangles = {{{-1, 0, -2}, {3, 0, -2}, {3, 4, 2}}, {{-1, 0, -2}, {3, 4, 2}, {-1, 4, 2}}};
  return s;
}

}  // namespace

TEST(OrbitCamera, EyeLiesOnTheSphereAndLooksAtThePivot) {
  const OrbitCamera o = sample();
  EXPECT_NEAR(glm::length(o.eye() - o.pivot), o.distance, 1e-4f);
  const Camera c = o.camera();
  expect_vec_near(c.forward, glm::normalize(o.pivot - o.eye()), 1e-6f);
  EXPECT_GT(c.up.y, 0.0f);
  EXPECT_NEAR(glm::dot(c.forward, c.up), 0.0f, 1e-6f);
  // yaw 0, pitch 0 puts the eye on +Z of the pivot.
  OrbitCamera z;
  expect_vec_near(z.eye(), {0.0f, 0.0f, 5.0f}, 1e-6f);
}

TEST(OrbitCamera, OrbitTurnsAboutThePivotAndClampsThePitch) {
  OrbitCamera o = sample();
  const glm::vec3 pivot = o.pivot;
  o.orbit(100.0f, 0.0f);  // drag right: yaw decreases
  EXPECT_NEAR(o.yaw, 0.7f - 100.0f * OrbitCamera::kRadiansPerPixel, 1e-5f);
  EXPECT_EQ(o.pivot, pivot);
  EXPECT_NEAR(glm::length(o.eye() - o.pivot), 10.0f, 1e-4f);
  o.orbit(0.0f, 1e6f);  // far past the pole
  EXPECT_FLOAT_EQ(o.pitch, OrbitCamera::kMaxPitch);
  // Still +Y up at the limit: look_at does not switch to +Z, so the view does not jump.
  EXPECT_GT(o.camera().up.y, 0.0f);
  o.orbit(0.0f, -1e6f);
  EXPECT_FLOAT_EQ(o.pitch, -OrbitCamera::kMaxPitch);
  o.orbit(1e5f, 0.0f);
  EXPECT_LE(std::abs(o.yaw), 3.1416f) << "yaw kept in (-pi, pi]";
}

TEST(OrbitCamera, PanMovesThePivotWithTheMouse) {
  OrbitCamera o = sample();
  const Camera before = o.camera();
  const int h = 600, w = 800;
  o.pan(40.0f, -25.0f, h);
  const Camera after = o.camera();
  EXPECT_NEAR(glm::length(o.eye() - o.pivot), 10.0f, 1e-3f);
  expect_vec_near(after.forward, before.forward, 1e-5f, "pan keeps the direction");
  // The world point that was under the pivot's pixel is now 40 px right of
  // the centre and 25 px above it: it follows the mouse.
  const glm::vec3 old_pivot = sample().pivot;
  const glm::vec3 d = old_pivot - after.position;
  const glm::vec3 right = glm::cross(after.forward, after.up);
  const float depth = glm::dot(d, after.forward);
  const float tan_half = std::tan(0.5f * o.yfov);
  const float px = (glm::dot(d, right) / depth / tan_half) * (0.5f * h);  // pixels right of the centre
  const float py = (glm::dot(d, after.up) / depth / tan_half) * (0.5f * h);
  EXPECT_NEAR(px, 40.0f, 1e-2f);
  EXPECT_NEAR(py, 25.0f, 1e-2f);  // dy = -25: the mouse went up
  (void)w;
}

TEST(OrbitCamera, ZoomMovesTowardsThePivotNeverThrough) {
  OrbitCamera o = sample();
  const glm::vec3 dir = glm::normalize(o.eye() - o.pivot);
  o.zoom(2.0f);
  EXPECT_NEAR(o.distance, 10.0f * OrbitCamera::kZoomPerStep * OrbitCamera::kZoomPerStep, 1e-4f);
  expect_vec_near(glm::normalize(o.eye() - o.pivot), dir, 1e-6f);
  o.zoom(-2.0f);
  EXPECT_NEAR(o.distance, 10.0f, 1e-4f);
  o.zoom(1e4f);
  EXPECT_GT(o.distance, 0.0f);
  EXPECT_TRUE(std::isfinite(glm::length(o.eye())));
}

TEST(OrbitCamera, SetPivotKeepsTheEye) {
  OrbitCamera o = sample();
  const glm::vec3 eye = o.eye();
  o.set_pivot({0.0f, 0.0f, 0.0f});
  expect_vec_near(o.eye(), eye, 1e-4f);
  expect_vec_near(o.pivot, {0, 0, 0}, 0.0f);
  EXPECT_NEAR(o.distance, glm::length(eye), 1e-4f);
  o.set_pivot(o.eye());  // on the eye: ignored
  expect_vec_near(o.pivot, {0, 0, 0}, 0.0f);
}

TEST(OrbitCamera, FrameFitsTheBoxInBothFieldsOfView) {
  OrbitCamera o = sample();
  const Aabb box{{-1, -2, -3}, {5, 2, 1}};
  const float aspect = 0.5f;  // portrait: the horizontal field decides
  o.frame(box, aspect);
  expect_vec_near(o.pivot, box.center(), 1e-6f);
  const float r = 0.5f * glm::length(box.extent());
  const float half_h = std::atan(std::tan(0.5f * o.yfov) * aspect);
  EXPECT_NEAR(o.distance, r / std::sin(half_h), 1e-3f);
  EXPECT_FLOAT_EQ(o.yaw, 0.7f) << "framing keeps the direction";
  // Same distance as core's frame_bounds for the same field of view.
  const Camera framed = frame_bounds(box, aspect, o.yfov);
  EXPECT_NEAR(glm::length(framed.position - box.center()), o.distance, 1e-3f);
}

TEST(OrbitCamera, FromCameraSeesWhatTheCameraSees) {
  const Camera cam = look_at({4.0f, 3.0f, 5.0f}, {0.0f, 1.0f, 0.0f}, 0.8f);
  const OrbitCamera o = OrbitCamera::from_camera(cam, 3.0f);
  expect_vec_near(o.eye(), cam.position, 1e-4f);
  expect_vec_near(o.camera().forward, cam.forward, 1e-5f);
  expect_vec_near(o.camera().up, cam.up, 1e-5f);
  EXPECT_NEAR(glm::length(o.pivot - cam.position), 3.0f, 1e-5f);
  EXPECT_FLOAT_EQ(o.yfov, 0.8f);
}

// A scene near the float range cannot be framed: the app keeps the orbit's
// default view and says why on the status line, instead of failing.
TEST(ViewCamera, DefaultOfAnUnframableSceneSaysWhy) {
  Scene s;
  s.triangles = {{{-3e38f, 0, 0}, {3e38f, 0, 0}, {0, 3e38f, 0}}};
  const ViewCamera v = ViewCamera::scene_default(s, 1.0f);
  EXPECT_NE(v.framing_problem.find("cannot frame the scene"), std::string::npos) << v.framing_problem;
  EXPECT_TRUE(v.is_default);
  EXPECT_TRUE(std::isfinite(v.camera().position.x));
  EXPECT_TRUE(ViewCamera::scene_default(box_scene(), 1.0f).framing_problem.empty());
}

TEST(ViewCamera, DefaultIsWhatRenderShowsWithoutACamera) {
  Scene s = box_scene();
  const float aspect = 4.0f / 3.0f;
  ViewCamera v = ViewCamera::scene_default(s, aspect);
  const Camera expected = camera_from_spec("", s, aspect);
  EXPECT_EQ(v.camera().position, expected.position);
  EXPECT_EQ(v.camera().forward, expected.forward);
  EXPECT_EQ(v.spec(), "");
  // The orbit takes over from the same place.
  expect_vec_near(v.orbit.eye(), expected.position, 1e-4f);
  expect_vec_near(v.orbit.pivot, s.bounds().center(), 1e-5f);

  Camera named = look_at({0, 10, 10}, {1, 2, 0}, 0.6f);
  named.name = "top";
  s.cameras = {named, look_at({5, 5, 5}, {0, 0, 0}, 0.7f)};
  v = ViewCamera::scene_default(s, aspect);
  EXPECT_EQ(v.camera().position, named.position);
  EXPECT_EQ(v.spec(), "") << "the scene's first camera is the default";
  v = ViewCamera::scene_camera_view(s, 1);
  EXPECT_EQ(v.spec(), "gltf:1");
  EXPECT_EQ(v.camera().position, s.cameras[1].position);
  v.unfix();
  EXPECT_NE(v.spec().find(','), std::string::npos) << "after a move the spec is eye,target,fov";
}

TEST(ViewCamera, SpecReproducesTheOrbitInRender) {
  const Scene s = box_scene();
  ViewCamera v;
  v.orbit = sample();
  const std::string spec = v.spec();
  const Camera reread = camera_from_spec(spec, s, 1.5f);
  const Camera shown = v.camera();
  expect_vec_near(reread.position, shown.position, 1e-5f);
  expect_vec_near(reread.forward, shown.forward, 1e-6f);
  expect_vec_near(reread.up, shown.up, 1e-6f);
  EXPECT_NEAR(reread.yfov, shown.yfov, 1e-6f);
  // A commanded camera is shown exactly and keeps its spec.
  const std::string cmd = "6,4,8,0,1.2,0,40";
  const ViewCamera c = ViewCamera::from_spec(cmd, s, 1.5f);
  EXPECT_EQ(c.spec(), cmd);
  EXPECT_EQ(c.camera().position, camera_from_spec(cmd, s, 1.5f).position);
  EXPECT_EQ(c.camera().forward, camera_from_spec(cmd, s, 1.5f).forward);
  expect_vec_near(c.orbit.pivot, {0.0f, 1.2f, 0.0f}, 1e-5f);
  EXPECT_THROW(ViewCamera::from_spec("gltf:3", s, 1.5f), std::invalid_argument);
  EXPECT_THROW(ViewCamera::from_spec("1,2,3", s, 1.5f), std::invalid_argument);
}
}  // namespace unity_test_app_orbit_camera
