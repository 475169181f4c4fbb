#pragma once
// Pinhole cameras: primary rays for image pixels, a default view that frames
// a bounding box, and the command line's camera spec.
#include "core/math/aabb.h"
#include "core/math/ray.h"
#include "core/scene/scene.h"

#include <string_view>

namespace accelviz {

/// Builds a camera at `eye` looking at `target`, with world +Y as up (or +Z
/// when the view is vertical). Throws std::invalid_argument when eye == target
/// or the values are not finite, or yfov is outside (0, 180) degrees.
Camera look_at(const glm::vec3& eye, const glm::vec3& target, float yfov_radians);

/// Aspect ratio (width / height) the camera uses for a W×H image: its own when
/// set, else the image's.
float camera_aspect(const Camera& cam, int width, int height);

/// Ray through the continuous image point (u, v): u in [0, 1] left to right,
/// v in [0, 1] top to bottom (image rows grow downwards, world up is at the
/// top). Unit direction, tmin 0, unbounded.
Ray camera_ray(const Camera& cam, float u, float v, float aspect);

/// Primary ray through the centre of pixel (x, y) of a W×H image
/// (x + 0.5, y + 0.5; row 0 at the top).
Ray primary_ray(const Camera& cam, int x, int y, int width, int height);

/// A view of `bounds` from a fixed diagonal direction (+1, +0.6, +1.4),
/// normalised, towards the box centre, far enough that the box's bounding
/// sphere fits both the vertical and the horizontal field of view. An empty
/// box gives the default camera.
/// Throws std::range_error ("cannot frame the scene: ...") for bounds so
/// large that the camera would stand beyond the float range.
Camera frame_bounds(const Aabb& bounds, float aspect, float yfov_radians = Camera{}.yfov);

/// The `--camera` option:
///  - ""                       scene's first camera, else frame_bounds(scene bounds)
///  - "ex,ey,ez,tx,ty,tz[,fov]" eye, target, optional vertical fov in degrees (default 45)
///  - "gltf:N"                 the scene's N-th camera (0-based)
/// Throws std::invalid_argument with a one-line message on a bad spec.
Camera camera_from_spec(std::string_view spec, const Scene& scene, float aspect);

}  // namespace accelviz
