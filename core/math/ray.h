#pragma once
// Rays and the per-ray constants that every traversal needs.
#include <glm/glm.hpp>

#include <cstdint>
#include <limits>

namespace accelviz {

inline constexpr float kInfinity = std::numeric_limits<float>::infinity();
/// Ray files write 1e30 for "unbounded"; the loaders map it to kInfinity.
inline constexpr float kRayFileUnbounded = 1e30f;

/// A ray segment origin + t·direction for t in [tmin, tmax].
/// inv_dir is precomputed once per ray (1/±0 gives ±inf, which the slab test
/// handles without NaN, see Aabb::intersect).
struct Ray {
  glm::vec3 origin{0.0f};
  float tmin = 0.0f;
  glm::vec3 direction{0.0f, 0.0f, 1.0f};
  float tmax = kInfinity;
  glm::vec3 inv_dir{kInfinity, kInfinity, 1.0f};

  Ray() = default;
  Ray(const glm::vec3& o, const glm::vec3& d, float t0 = 0.0f, float t1 = kInfinity)
      : origin(o), tmin(t0), direction(d), tmax(t1), inv_dir(1.0f / d.x, 1.0f / d.y, 1.0f / d.z) {}

  glm::vec3 at(float t) const { return origin + t * direction; }
};

/// 1 + 2·gamma(3) (pbrt-v4 / Ize 2013): scaling the slab exit distance by this
/// makes the float slab test conservative, so rounding never produces a false
/// miss of a box the exact ray touches.
inline constexpr float kSlabExitScale = 1.0f + 2.0f * (3.0f * std::numeric_limits<float>::epsilon() * 0.5f) /
                                                   (1.0f - 3.0f * std::numeric_limits<float>::epsilon() * 0.5f);

/// Sentinel for "no primitive".
inline constexpr std::uint32_t kInvalidId = 0xFFFFFFFFu;

}  // namespace accelviz
