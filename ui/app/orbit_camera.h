#pragma once
// The 3D view's camera: an orbit around a pivot (left-drag orbits, pan
// moves the pivot in the view plane, the wheel scales the distance to the
// pivot), plus the scene's own cameras shown exactly until the user moves.
// Produces core Cameras through look_at(), so a view is reproduced by
// `accelviz render --camera ex,ey,ez,tx,ty,tz,fov` with the eye and pivot.
#include "core/math/aabb.h"
#include "core/scene/scene.h"

#include <glm/glm.hpp>

#include <optional>
#include <string>

namespace accelviz {

struct OrbitCamera {
  /// Elevation limit: look_at() switches its up vector from +Y to +Z when the
  /// view is within 2.6° of vertical, which would make the view jump.
  static constexpr float kMaxPitch = 1.5184364f;  // 87°
  static constexpr float kRadiansPerPixel = 0.008f;
  static constexpr float kZoomPerStep = 0.85f;  ///< distance factor per wheel step towards the pivot

  glm::vec3 pivot{0.0f};
  float distance = 5.0f;       ///< eye to pivot, > 0
  float yaw = 0.0f;            ///< about +Y; 0 puts the eye on +Z of the pivot
  float pitch = 0.0f;          ///< elevation of the eye above the pivot, |pitch| <= kMaxPitch
  float yfov = Camera{}.yfov;  ///< 0.8 rad, as `accelviz render`'s default framing

  /// pivot + distance · (cos p sin y, sin p, cos p cos y).
  glm::vec3 eye() const;
  /// look_at(eye, pivot, yfov): world +Y up, aspect from the image.
  Camera camera() const;

  /// Left-drag by (dx, dy) pixels: right turns the scene right, down tilts it towards the viewer.
  void orbit(float dx_px, float dy_px);
  /// Moves pivot and eye in the view plane so that the point at the pivot's
  /// depth follows the mouse (`viewport_height` in the same pixels as dx, dy).
  void pan(float dx_px, float dy_px, int viewport_height);
  /// Wheel: positive steps move towards the pivot (never through it).
  void zoom(float steps);
  /// New pivot, same eye (double-click on a surface).
  void set_pivot(const glm::vec3& p);
  /// Keeps the direction; centres `box` and backs off until its bounding
  /// sphere fits both fields of view (as core's frame_bounds does).
  void frame(const Aabb& box, float aspect);

  /// The orbit that sees what `cam` sees, pivoting at `pivot_distance`
  /// along its view direction (the roll of a tilted camera is dropped).
  static OrbitCamera from_camera(const Camera& cam, float pivot_distance);
};

/// What the 3D view shows: the orbit, or a fixed camera (a scene camera, or
/// the default framing) shown exactly until the first orbit/pan/zoom.
struct ViewCamera {
  OrbitCamera orbit;
  std::optional<Camera> fixed;
  int scene_camera = -1;     ///< index into Scene::cameras while `fixed` is one of them
  bool is_default = false;   ///< `fixed` is the default view (what `render` shows without --camera)
  std::string command_spec;  ///< `fixed` came from a --camera style spec (script `camera`): that spec
  /// scene_default could not frame the scene (bounds near the float range):
  /// why, for the status line; the view is then the orbit's default.
  std::string framing_problem;

  Camera camera() const { return fixed ? *fixed : orbit.camera(); }
  /// Leaves the fixed camera for the orbit (called before every user move).
  void unfix();

  /// The scene's first camera, else the framing of its bounds: what
  /// `accelviz render` shows without --camera; the R/Home view.
  static ViewCamera scene_default(const Scene& scene, float aspect);
  /// Scene camera `index` (must exist).
  static ViewCamera scene_camera_view(const Scene& scene, int index);
  /// A `--camera` spec ("", "gltf:N", "ex,ey,ez,tx,ty,tz[,fov]") as core's
  /// camera_from_spec reads it; throws std::invalid_argument on a bad spec.
  static ViewCamera from_spec(const std::string& spec, const Scene& scene, float aspect);

  /// The `--camera` value that reproduces this view: "" for the default,
  /// "gltf:N" for an untouched scene camera, else "ex,ey,ez,tx,ty,tz,fov".
  std::string spec() const;
};

/// "ex,ey,ez,tx,ty,tz,fov" for any camera (the target one unit along its
/// view): a `--camera` value for a view that no longer is the window's.
std::string explicit_camera_spec(const Camera& camera);

}  // namespace accelviz
