#pragma once
// Seeded std::mt19937 helpers shared by the BVH tests: one definition
// instead of one per test file.
#include <glm/glm.hpp>
#include <random>

namespace accelviz::test_random {

/// Uniform float in [0, 1) from the raw engine output (std::uniform_real_distribution
/// is implementation-defined; this keeps scenes identical across standard libraries).
inline float uniform(std::mt19937& rng) {
  return static_cast<float>(rng() >> 8) * (1.0f / 16777216.0f);
}

/// A random unit vector (rejection sampling in the unit ball's shell).
inline glm::vec3 random_direction(std::mt19937& rng) {
  for (;;) {
    const glm::vec3 d{2 * uniform(rng) - 1, 2 * uniform(rng) - 1, 2 * uniform(rng) - 1};
    const float l = glm::length(d);
    if (l > 0.05f && l <= 1.0f) return d / l;
  }
}

}  // namespace accelviz::test_random
