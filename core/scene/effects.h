#pragma once
// Effects by scene: the app inspects the loaded scene and runs only what it
// calls for, with a one-line reason for each decision:
//  - shadow-rays: any-hit rays toward the lights, only when the scene has lights;
//  - per-frame-updates: only when something animates (TRS channels or a
//    deforming mesh), and then only what moved;
//  - two-level: the TLAS/BLAS structure only when some mesh is instanced
//    more than once (otherwise one flattened BVH does the same work);
//  - textures: never decoded (no view draws them; the glTF loader skips
//    images), and cannot be forced on.
// The user can force any forceable effect on. `accelviz info` prints the
// list; the GUI's Scene panel shows it. run_frame() is the frame loop that
// honours the decisions and counts what it did, so tests can check them.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/accel/accel.h"
#include "core/scene/animation.h"
#include "core/scene/scene.h"

namespace accelviz {

struct Effect {
  std::string name;  ///< "shadow-rays", "per-frame-updates", "two-level", "textures"
  bool on = false;
  bool forced = false;    ///< on because the user asked, not because the scene calls for it
  bool forceable = true;  ///< false: asking for it changes nothing (see reason)
  std::string reason;     ///< why on or off, one line
};

/// User overrides: force an effect on even when the scene does not call for it.
struct EffectForces {
  bool shadow_rays = false;
  bool per_frame_updates = false;
  bool two_level = false;
  bool textures = false;  ///< not forceable: recorded in the reason
};

struct SceneEffects {
  Effect shadow_rays, per_frame_updates, two_level, textures;

  std::vector<Effect> list() const { return {shadow_rays, per_frame_updates, two_level, textures}; }
  /// The structure the app should build: "tlas" when two-level is on, else FALLBACK.
  std::string structure(const std::string& fallback = "bvh") const { return two_level.on ? "tlas" : fallback; }
};

SceneEffects decide_effects(const Scene& scene, const EffectForces& forces = {});

/// Sets the force named NAME ("shadow-rays", ...); false for an unknown name.
bool set_force(EffectForces& forces, const std::string& name);

/// "name  on|off  [forced]  reason" lines, for `accelviz info`.
std::string effects_text(const SceneEffects& effects);

/// The scene's lights that give light (intensity and colour above 0): a
/// light of intensity 0 lights nothing and casts no shadow.
std::vector<Light> casting_lights(const Scene& scene);

/// Whether shadow rays are traced: the scene has a light that gives light
/// (casting_lights), or the user forced them on (what decide_effects()
/// says, without the rest of its work).
bool shadow_rays_wanted(const Scene& scene, const EffectForces& forces);

/// The point light shadow rays aim at in a scene without lights, wherever
/// they are asked for (forced in the app; the shadow rays of `bench`, `rays`,
/// `sweep` and the benchmarks): named "synthetic", above the box centre by
/// the box's bounding radius and half that towards the default camera's
/// side: horizontally towards `eye` (the scene's first camera), else the
/// framing view's side (+x, +z); at (0, 10, 0) for an empty box.
Light synthetic_light(const Aabb& bounds, std::optional<glm::vec3> eye = std::nullopt);
/// synthetic_light of the scene's bounds, towards its first camera if any.
Light synthetic_light(const Scene& scene);

/// The lights shadow rays aim at: the scene's that give light, or, in a
/// scene without any, synthetic_light(scene). Empty when WANTED is false.
std::vector<Light> shadow_lights(const Scene& scene, bool wanted);

/// The shadow (any-hit) ray from PRIMARY's hit H toward L: starts a little
/// off the surface on the side the primary came from; ends at a point
/// light (t in [0, 1]) or runs to infinity against a directional one.
Ray shadow_ray(const Ray& primary, const Hit& h, const Light& l);

/// What one frame did.
struct FrameCounters {
  std::uint64_t primary_rays = 0;
  std::uint64_t shadow_rays = 0;
  std::uint64_t refits = 0;
  std::uint64_t rebuilds = 0;
  std::uint64_t tlas_rebuilds = 0;
  std::uint64_t moved_instances = 0;
};

/// One frame at time T: the animator steps only when per-frame updates are
/// on (ANIMATOR may be null), WIDTH x HEIGHT primary rays from CAMERA are
/// traced on ACCEL, and for each primary hit one shadow ray per light of
/// shadow_lights() when shadow rays are on (a synthetic light when forced
/// without lights).
FrameCounters run_frame(const Scene& scene, const SceneEffects& effects, const Accelerator& accel, const Camera& camera,
                        int width, int height, SceneAnimator* animator, float t);

}  // namespace accelviz
