#pragma once
// From accelviz::Camera to GL matrices, in the one convention the CPU ray
// tracer uses as well:
//  - image pixel (x, y) covers [x, x+1) × [y, y+1); its primary ray goes
//    from the pinhole (Camera::position) through (x + 0.5, y + 0.5);
//  - y = 0 is the TOP row of the image;
//  - the image plane spans tan(yfov/2) up and down and aspect·tan(yfov/2)
//    left and right at unit distance along `forward`, with right =
//    forward × up and aspect = width/height when Camera::aspect is 0.
// This is core/query/camera.h's primary_ray; glm::lookAt + glm::perspective
// give exactly this (GL puts y = 0 at the bottom; RenderTarget::read_pixels
// flips rows so images start at the top).
#include "core/math/aabb.h"
#include "core/scene/scene.h"

#include <glm/glm.hpp>

#include <optional>

namespace accelviz {

struct CameraMatrices {
  glm::mat4 view{1.0f};
  glm::mat4 projection{1.0f};
  glm::mat4 view_projection{1.0f};
  glm::vec3 eye{0.0f};
  int width = 0;  ///< image size the projection was made for
  int height = 0;
};

struct ClipPlanes {
  float z_near = 0.01f;
  float z_far = 100.0f;
};
/// Near/far planes that keep all of `bounds` visible from `camera` with
/// good depth precision (ratio at most 1e5); defaults for an empty box.
ClipPlanes fit_clip_planes(const Camera& camera, const Aabb& bounds);

/// View and projection for an image of width × height pixels.
CameraMatrices camera_matrices(const Camera& camera, int width, int height, const ClipPlanes& clip);

/// Where a world point lands in the image, in continuous pixel coordinates
/// of the convention above (x right, y down; pixel (i, j)'s centre is
/// (i + 0.5, j + 0.5)). Empty when the point is behind the eye.
std::optional<glm::vec2> project_to_pixel(const CameraMatrices& m, const glm::vec3& world);

}  // namespace accelviz
