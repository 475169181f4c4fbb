#pragma once
// Refit decay: how a BVH's quality falls when it is refitted frame after
// frame instead of rebuilt, on deterministic smooth vertex motion, and what
// a rebuild-when-worse-than-R rule costs and saves. Per frame: refit time,
// rebuild time, SAH of the refitted tree and of a fresh build, and the
// measured traversal cost (nodes and triangle tests per ray) of both on a
// fixed ray set.
#include "core/accel/bvh/bvh.h"

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

namespace accelviz {

/// Vertex positions at `time` (in periods): every vertex moves along its own
/// seeded direction by amplitude · sin(2π(time + phase)), with the direction
/// and phase hashed from its rest position, so vertices shared by several
/// triangles move together and closed meshes stay closed.
std::vector<Triangle> animate_vertices(std::span<const Triangle> rest, float amplitude, double time,
                                       std::uint64_t seed);

struct RefitDecayOptions {
  int frames = 30;                 ///< frames after the rest pose (>= 1)
  float amplitude = 0.02f;         ///< motion amplitude relative to the scene's bounding-box diagonal
  double frame_step = 0.05;        ///< time advance per frame, in motion periods
  double rebuild_ratio = 0;        ///< > 0: rebuild when refit SAH / fresh SAH exceeds it; 0: never
  std::uint64_t seed = 1;          ///< motion phases and directions
  BvhOptions bvh;                  ///< build options (compute_epo is turned off: per-frame EPO would dominate)
  unsigned threads = 0;            ///< tracing threads (0: all hardware threads)
};

struct RefitFrame {
  int frame = 0;                 ///< 1-based
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
  std::vector<RefitFrame> frames;
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
