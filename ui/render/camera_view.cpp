#include "ui/render/camera_view.h"

#include "core/query/camera.h"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace accelviz {

ClipPlanes fit_clip_planes(const Camera& camera, const Aabb& bounds) {
  if (bounds.is_empty()) return {};
  // Distances of the box corners along the view direction bound what can be
  // visible; a margin keeps boxes drawn exactly on the bounds inside.
  const glm::vec3 f = glm::normalize(camera.forward);
  float nearest = std::numeric_limits<float>::infinity();
  float farthest = -std::numeric_limits<float>::infinity();
  for (int i = 0; i < 8; ++i) {
    const glm::vec3 corner{(i & 1) ? bounds.hi.x : bounds.lo.x, (i & 2) ? bounds.hi.y : bounds.lo.y,
                           (i & 4) ? bounds.hi.z : bounds.lo.z};
    const float d = glm::dot(corner - camera.position, f);
    nearest = std::min(nearest, d);
    farthest = std::max(farthest, d);
  }
  const float diagonal = glm::length(bounds.extent());
  ClipPlanes clip;
  clip.z_far = std::max(farthest, 0.0f) + 0.01f * diagonal + 1e-3f;
  // Inside the box (or close): the near plane cannot follow the nearest
  // corner, so it is limited by depth precision instead.
  clip.z_near = std::max(nearest - 0.01f * diagonal, clip.z_far * 1e-5f);
  return clip;
}

CameraMatrices camera_matrices(const Camera& camera, int width, int height, const ClipPlanes& clip) {
  CameraMatrices m;
  m.width = width;
  m.height = height;
  m.eye = camera.position;
  m.view = glm::lookAt(camera.position, camera.position + camera.forward, camera.up);
  m.projection = glm::perspective(camera.yfov, camera_aspect(camera, width, height), clip.z_near, clip.z_far);
  m.view_projection = m.projection * m.view;
  return m;
}

std::optional<glm::vec2> project_to_pixel(const CameraMatrices& m, const glm::vec3& world) {
  const glm::vec4 clip = m.view_projection * glm::vec4(world, 1.0f);
  if (clip.w <= 0.0f) return std::nullopt;
  const glm::vec2 ndc = glm::vec2(clip) / clip.w;
  // NDC y points up; image rows count down from the top.
  return glm::vec2((ndc.x * 0.5f + 0.5f) * static_cast<float>(m.width),
                   (0.5f - ndc.y * 0.5f) * static_cast<float>(m.height));
}

}  // namespace accelviz
