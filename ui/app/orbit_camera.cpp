#include "ui/app/orbit_camera.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/query/camera.h"
#include "ui/app/app_config.h"

namespace accelviz {
namespace {

constexpr float kMinDistance = 1e-5f;
constexpr float kMaxDistance = 1e8f;

// A pivot distance for a camera that says nothing about what it looks at:
// the scene centre's depth along the view, but never less than a tenth of
// the scene's size (a camera inside the scene still orbits sensibly).
float pivot_distance_for(const Camera& cam, const Aabb& bounds) {
  if (bounds.is_empty()) return 5.0f;
  const float diag = glm::length(bounds.extent());
  const float along = glm::dot(bounds.center() - cam.position, cam.forward);
  return std::max({along, 0.1f * diag, kMinDistance * 10.0f});
}

}  // namespace

glm::vec3 OrbitCamera::eye() const {
  const float cp = std::cos(pitch);
  return pivot + distance * glm::vec3(cp * std::sin(yaw), std::sin(pitch), cp * std::cos(yaw));
}

Camera OrbitCamera::camera() const {
  Camera cam = look_at(eye(), pivot, yfov);
  cam.name = "orbit";
  return cam;
}

void OrbitCamera::orbit(float dx_px, float dy_px) {
  yaw -= dx_px * kRadiansPerPixel;
  // Keep yaw in (-pi, pi] so it stays precise after many turns.
  yaw = std::remainder(yaw, 2.0f * 3.14159265f);
  pitch = std::clamp(pitch + dy_px * kRadiansPerPixel, -kMaxPitch, kMaxPitch);
}

void OrbitCamera::pan(float dx_px, float dy_px, int viewport_height) {
  if (viewport_height <= 0) return;
  const Camera cam = camera();
  const glm::vec3 right = glm::cross(cam.forward, cam.up);
  // World units per pixel at the pivot's depth: the image plane at distance d
  // spans 2·d·tan(yfov/2) vertically over viewport_height pixels.
  const float per_px = 2.0f * distance * std::tan(0.5f * yfov) / static_cast<float>(viewport_height);
  pivot += (-dx_px * right + dy_px * cam.up) * per_px;
}

void OrbitCamera::zoom(float steps) {
  distance = std::clamp(distance * std::pow(kZoomPerStep, steps), kMinDistance, kMaxDistance);
}

void OrbitCamera::set_pivot(const glm::vec3& p) {
  const glm::vec3 e = eye();
  const glm::vec3 d = e - p;
  const float len = glm::length(d);
  if (!(len > kMinDistance) || !std::isfinite(len)) return;  // eye on the pivot: keep the old one
  pivot = p;
  distance = len;
  pitch = std::clamp(std::asin(std::clamp(d.y / len, -1.0f, 1.0f)), -kMaxPitch, kMaxPitch);
  yaw = std::atan2(d.x, d.z);
}

void OrbitCamera::frame(const Aabb& box, float aspect) {
  if (box.is_empty()) return;
  float radius = 0.5f * glm::length(box.extent());
  if (!(radius > 0.0f)) radius = 1.0f;
  const float half_v = 0.5f * yfov;
  const float half_h = std::atan(std::tan(half_v) * (aspect > 0.0f ? aspect : 1.0f));
  pivot = box.center();
  distance = std::clamp(radius / std::sin(std::min(half_v, half_h)), kMinDistance, kMaxDistance);
}

OrbitCamera OrbitCamera::from_camera(const Camera& cam, float pivot_distance) {
  OrbitCamera o;
  o.yfov = cam.yfov;
  o.distance = std::clamp(pivot_distance, kMinDistance, kMaxDistance);
  o.pivot = cam.position + cam.forward * o.distance;
  const glm::vec3 back = -cam.forward;
  o.pitch = std::clamp(std::asin(std::clamp(back.y, -1.0f, 1.0f)), -kMaxPitch, kMaxPitch);
  o.yaw = std::atan2(back.x, back.z);
  return o;
}

void ViewCamera::unfix() {
  fixed.reset();
  scene_camera = -1;
  is_default = false;
  command_spec.clear();
}

ViewCamera ViewCamera::scene_default(const Scene& scene, float aspect) {
  if (!scene.cameras.empty()) {
    ViewCamera v = scene_camera_view(scene, 0);
    v.is_default = true;
    return v;
  }
  ViewCamera v;
  const Aabb bounds = scene.bounds();
  Camera framed;
  try {
    framed = frame_bounds(bounds, aspect, v.orbit.yfov);
  } catch (const std::range_error& e) {
    v.framing_problem = e.what();
    v.is_default = true;
    return v;
  }
  v.orbit = OrbitCamera::from_camera(framed, bounds.is_empty() ? 5.0f : glm::length(bounds.center() - framed.position));
  if (!bounds.is_empty()) v.orbit.pivot = bounds.center();
  v.fixed = framed;
  v.is_default = true;
  return v;
}

ViewCamera ViewCamera::scene_camera_view(const Scene& scene, int index) {
  ViewCamera v;
  const Camera& cam = scene.cameras.at(static_cast<std::size_t>(index));
  v.orbit = OrbitCamera::from_camera(cam, pivot_distance_for(cam, scene.bounds()));
  v.fixed = cam;
  v.scene_camera = index;
  return v;
}

ViewCamera ViewCamera::from_spec(const std::string& spec, const Scene& scene, float aspect) {
  if (spec.empty()) return scene_default(scene, aspect);
  const Camera cam = camera_from_spec(spec, scene, aspect);  // validates the spec (and N of gltf:N)
  if (spec.rfind("gltf:", 0) == 0) return scene_camera_view(scene, std::stoi(spec.substr(5)));
  // Shown exactly as `render --camera` computes it; the orbit pivots at the
  // target the spec names (its fields 4..6), at the eye's distance.
  float f[6] = {};
  std::size_t pos = 0;
  for (int k = 0; k < 6; ++k) {
    const auto comma = spec.find(',', pos);
    f[k] = std::stof(spec.substr(pos, comma == std::string::npos ? std::string::npos : comma - pos));
    pos = comma == std::string::npos ? spec.size() : comma + 1;
  }
  ViewCamera v;
  v.fixed = cam;
  v.command_spec = spec;
  v.orbit = OrbitCamera::from_camera(cam, glm::length(glm::vec3(f[3], f[4], f[5]) - cam.position));
  return v;
}

std::string explicit_camera_spec(const Camera& cam) {
  const glm::vec3 e = cam.position, t = cam.position + cam.forward;
  std::string s;
  for (float x : {e.x, e.y, e.z, t.x, t.y, t.z}) s += format_number(x) + ",";
  return s + format_number(cam.yfov * 180.0 / 3.14159265358979);
}

std::string ViewCamera::spec() const {
  if (fixed && is_default) return "";
  if (fixed && scene_camera >= 0) return "gltf:" + std::to_string(scene_camera);
  if (fixed && !command_spec.empty()) return command_spec;
  const Camera cam = camera();
  // A fixed camera that is neither (not produced today) still reproduces:
  // any point along its view serves as the target.
  const glm::vec3 e = cam.position;
  const glm::vec3 t = fixed ? cam.position + cam.forward : orbit.pivot;
  std::string s;
  for (float x : {e.x, e.y, e.z, t.x, t.y, t.z}) s += format_number(x) + ",";
  return s + format_number(cam.yfov * 180.0 / 3.14159265358979);
}

}  // namespace accelviz
