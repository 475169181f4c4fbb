#include "core/query/camera.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

namespace accelviz {

namespace {

constexpr float kPi = 3.14159265358979f;
constexpr float kDefaultFovDegrees = 45.0f;

bool finite3(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

/// Splits on commas and parses each field as a float; false on any bad field.
bool parse_floats(std::string_view s, std::vector<float>& out) {
  out.clear();
  while (true) {
    const std::size_t comma = s.find(',');
    std::string field(s.substr(0, comma));
    // Tolerate spaces around values ("1, 2, 3").
    const std::size_t b = field.find_first_not_of(' ');
    const std::size_t e = field.find_last_not_of(' ');
    if (b == std::string::npos) return false;
    field = field.substr(b, e - b + 1);
    float v = 0.0f;
    const char* first = field.data();
    const char* last = field.data() + field.size();
    if (*first == '+') ++first;
    const auto [ptr, ec] = std::from_chars(first, last, v);
    if (ec != std::errc() || ptr != last) return false;
    out.push_back(v);
    if (comma == std::string_view::npos) return true;
    s = s.substr(comma + 1);
  }
}

}  // namespace

Camera look_at(const glm::vec3& eye, const glm::vec3& target, float yfov_radians) {
  if (!finite3(eye) || !finite3(target)) throw std::invalid_argument("camera: eye and target must be finite");
  const glm::vec3 d = target - eye;
  // The length in double: |d|² overflows float from about 1e19, d itself only near 3.4e38.
  const double len = glm::length(glm::dvec3(d));
  if (!(len > 0.0)) throw std::invalid_argument("camera: eye and target are the same point");
  if (!finite3(d) || !std::isfinite(static_cast<float>(len)))
    throw std::invalid_argument("camera: eye and target lie too far apart (their distance overflows float)");
  if (!(yfov_radians > 0.0f && yfov_radians < kPi))
    throw std::invalid_argument("camera: vertical field of view must lie strictly between 0 and 180 degrees");
  Camera cam;
  cam.position = eye;
  cam.forward = glm::vec3(glm::dvec3(d) / len);
  // World +Y is up unless the view looks (nearly) straight up or down.
  glm::vec3 world_up(0.0f, 1.0f, 0.0f);
  if (std::abs(glm::dot(cam.forward, world_up)) > 0.999f) world_up = glm::vec3(0.0f, 0.0f, 1.0f);
  const glm::vec3 right = glm::normalize(glm::cross(cam.forward, world_up));
  cam.up = glm::cross(right, cam.forward);
  cam.yfov = yfov_radians;
  cam.aspect = 0.0f;
  return cam;
}

float camera_aspect(const Camera& cam, int width, int height) {
  if (cam.aspect > 0.0f) return cam.aspect;
  return height > 0 ? static_cast<float>(width) / static_cast<float>(height) : 1.0f;
}

Ray camera_ray(const Camera& cam, float u, float v, float aspect) {
  const float tan_half = std::tan(0.5f * cam.yfov);
  const glm::vec3 right = glm::cross(cam.forward, cam.up);
  const float sx = (2.0f * u - 1.0f) * tan_half * aspect;
  const float sy = (1.0f - 2.0f * v) * tan_half;
  const glm::vec3 dir = glm::normalize(cam.forward + sx * right + sy * cam.up);
  return Ray(cam.position, dir, 0.0f, kInfinity);
}

Ray primary_ray(const Camera& cam, int x, int y, int width, int height) {
  const float u = (static_cast<float>(x) + 0.5f) / static_cast<float>(width);
  const float v = (static_cast<float>(y) + 0.5f) / static_cast<float>(height);
  return camera_ray(cam, u, v, camera_aspect(cam, width, height));
}

Camera frame_bounds(const Aabb& bounds, float aspect, float yfov_radians) {
  if (bounds.is_empty()) {
    Camera cam;
    cam.yfov = yfov_radians;
    return cam;
  }
  const glm::vec3 centre = bounds.center();
  // In double: |extent|² overflows float from about 1e19, though a camera at a
  // few times that distance is representable.
  float radius = static_cast<float>(0.5 * glm::length(glm::dvec3(bounds.extent())));
  if (!(radius > 0.0f)) radius = 1.0f;  // a single point: any sensible distance
  // The sphere fits a cone of half-angle a when distance = r / sin(a); the
  // narrower of the two half-angles decides.
  const float half_v = 0.5f * yfov_radians;
  const float half_h = std::atan(std::tan(half_v) * (aspect > 0.0f ? aspect : 1.0f));
  const float half = std::min(half_v, half_h);
  const float distance = radius / std::sin(half);
  const glm::vec3 from = glm::normalize(glm::vec3(1.0f, 0.6f, 1.4f));
  const glm::vec3 eye = centre + from * distance;
  // Bounds near the float range (coordinates of 1e38, say) overflow the
  // radius or the camera's distance: no float camera sees them.
  if (!finite3(centre) || !std::isfinite(distance) || !finite3(eye)) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "(%g, %g, %g) .. (%g, %g, %g)", bounds.lo.x, bounds.lo.y, bounds.lo.z, bounds.hi.x,
                  bounds.hi.y, bounds.hi.z);
    throw std::range_error(std::string("cannot frame the scene: a camera that sees its bounds ") + buf +
                           " would stand beyond the float range");
  }
  Camera cam = look_at(eye, centre, yfov_radians);
  cam.name = "framed";
  return cam;
}

Camera camera_from_spec(std::string_view spec, const Scene& scene, float aspect) {
  if (spec.empty()) {
    if (!scene.cameras.empty()) return scene.cameras.front();
    return frame_bounds(scene.bounds(), aspect);
  }
  if (spec.rfind("gltf:", 0) == 0) {
    const std::string_view num = spec.substr(5);
    std::size_t index = 0;
    const auto [ptr, ec] = std::from_chars(num.data(), num.data() + num.size(), index);
    if (num.empty() || ec != std::errc() || ptr != num.data() + num.size())
      throw std::invalid_argument("camera '" + std::string(spec) + "': expected gltf:N with N a camera index");
    if (index >= scene.cameras.size())
      throw std::invalid_argument("camera '" + std::string(spec) + "': the scene has " +
                                  std::to_string(scene.cameras.size()) + " camera(s)");
    return scene.cameras[index];
  }
  std::vector<float> v;
  if (!parse_floats(spec, v) || (v.size() != 6 && v.size() != 7))
    throw std::invalid_argument("camera '" + std::string(spec) +
                                "': expected ex,ey,ez,tx,ty,tz[,fov_degrees] or gltf:N");
  const float fov_deg = v.size() == 7 ? v[6] : kDefaultFovDegrees;
  try {
    Camera cam = look_at({v[0], v[1], v[2]}, {v[3], v[4], v[5]}, fov_deg * kPi / 180.0f);
    cam.name = "command line";
    return cam;
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("camera '" + std::string(spec) + "': " + std::string(e.what()).substr(8));
  }
}

}  // namespace accelviz
