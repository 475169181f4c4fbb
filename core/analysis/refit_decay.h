#pragma once
// Refit decay: how a BVH's quality falls when it is refitted frame after
// frame instead of rebuilt, on deterministic smooth vertex motion, and what
// a rebuild-when-worse-than-R rule costs and saves. Per frame: refit time,
// rebuild time, SAH of the refitted tree and of a fresh build, and the
// measured traversal cost (nodes and triangle tests per ray) of both on a
// fixed ray set.
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "core/accel/bvh/bvh.h"

namespace accelviz {

/// Vertex positions at `time` (in periods): every vertex moves along its own
/// seeded direction by amplitude · (sin(2π(time + phase)) − sin(2π·phase)),
/// with the direction and phase hashed from its rest position, so vertices
/// shared by several triangles move together and closed meshes stay closed.
/// Time 0 is the rest pose; a vertex is at most 2 · amplitude from it, and
/// back at every whole period.
std::vector<Triangle> animate_vertices(std::span<const Triangle> rest, float amplitude, double time,
                                       std::uint64_t seed);

/// The synthetic motions of the refit experiment, each starting at the rest
/// pose and back at every whole period:
/// - jitter: animate_vertices (every vertex on its own: the mesh crumples, a
///   fresh tree degrades almost as much as the refitted one);
/// - explode: every triangle moves rigidly along its own seeded direction by
///   amplitude · (sin(2π(time + phase)) − sin(2π·phase)), direction and phase
///   hashed from its rest vertices (triangles keep their shape and drift apart
///   and through each other: the tree's grouping goes stale, the classic decay);
/// - wave: a smooth bend, every vertex displaced along one seeded direction by
///   amplitude · (sin(2π(time + k·p)) − sin(2π k·p)) with k a seeded wave vector
///   of one wavelength across the scene (neighbours move alike: refit holds).
enum class RefitMotion { jitter, explode, wave };
std::string_view refit_motion_name(RefitMotion m);  ///< "jitter", "explode", "wave"
std::optional<RefitMotion> parse_refit_motion(std::string_view name);

/// Triangles at `time` under `motion` (amplitude in scene units; `diagonal`
/// is the scene's bounding-box diagonal, the wave's wavelength).
std::vector<Triangle> animate_triangles(std::span<const Triangle> rest, RefitMotion motion, float amplitude,
                                        float diagonal, double time, std::uint64_t seed);

struct RefitDecayOptions {
  int frames = 30;                 ///< frames after the rest pose (>= 1)
  RefitMotion motion = RefitMotion::explode;
  float amplitude = 0.02f;         ///< motion amplitude relative to the scene's bounding-box diagonal
  double frame_step = 0.05;        ///< time advance per frame, in motion periods
  double rebuild_ratio = 0;        ///< > 0: rebuild when refit SAH / fresh SAH exceeds it; 0: never
  std::uint64_t seed = 1;          ///< motion phases and directions
  BvhOptions bvh;                  ///< build options (compute_epo is turned off: per-frame EPO would dominate)
  unsigned threads = 0;            ///< tracing threads (0: all hardware threads)
};

struct RefitFrame {
  int frame = 0;                 ///< 0: the rest pose the first tree was built on (ratio 1), then 1, 2, ...
  double refit_ms = 0;           ///< refitting the tree in use
  double rebuild_ms = 0;         ///< the fresh build's own build time
  double sah_refit = 0;          ///< SAH of the refitted tree (before any rebuild this frame)
  double sah_fresh = 0;          ///< SAH of a fresh build on this frame's vertices
  double ratio = 0;              ///< sah_refit / sah_fresh
  int refits_since_build = 0;    ///< how many refits the tree in use had had (this frame's included)
  double nodes_per_ray_refit = 0, prims_per_ray_refit = 0;  ///< refitted tree on the fixed rays
  double nodes_per_ray_fresh = 0, prims_per_ray_fresh = 0;  ///< fresh tree on the same rays
  bool rebuilt = false;          ///< the rule replaced the refitted tree by the fresh one
};

struct RefitDecayResult {
  std::vector<RefitFrame> frames;  ///< frame 0 (the rest pose: no refit, rebuild_ms the first build's) and 1..frames
  int rebuilds = 0;
};

/// Produces the triangles of frame k (1-based); same count and order as the rest pose.
using FrameSource = std::function<std::vector<Triangle>(int frame)>;

/// Runs the decay experiment. `rays` are traced (closest hit, counting pass)
/// against both trees every frame; they may be empty. With an empty `source`
/// the frames come from animate_vertices with the options' motion.
RefitDecayResult run_refit_decay(std::span<const Triangle> rest, std::span<const Ray> rays,
                                 const RefitDecayOptions& opts, const FrameSource& source = {});

}  // namespace accelviz
