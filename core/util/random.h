#pragma once
// Reproducible random numbers: SplitMix64 (Steele, Lea & Flood, "Fast
// splittable pseudorandom number generators", OOPSLA 2014; constants as in
// Vigna's public-domain reference) with explicit bit-to-float conversions, so
// a seed gives the same values on every machine and compiler (the standard
// library's distributions are implementation-defined). Used by the
// procedural scenes (core/scene/procedural/random.h), ray sets, sweeps,
// verification, calibration and the robustness lab.
#include <glm/glm.hpp>

#include <cstdint>

namespace accelviz {

inline constexpr std::uint64_t kGolden64 = 0x9E3779B97F4A7C15ull;  ///< SplitMix64's Weyl increment

/// SplitMix64's finaliser: a bijective mix of 64 bits.
inline std::uint64_t mix64(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

/// SplitMix64: one 64-bit state, a Weyl sequence scrambled by a bijective mix.
class SplitMix64 {
 public:
  explicit SplitMix64(std::uint64_t seed) : state_(seed) {}

  std::uint64_t next() { return mix64(state_ += kGolden64); }
  /// Uniform in [0, 1): the top 24 bits, so every value is an exact float.
  float uniform() { return static_cast<float>(next() >> 40) * 0x1.0p-24f; }
  /// Uniform in [lo, hi).
  float uniform(float lo, float hi) { return lo + (hi - lo) * uniform(); }
  /// Two or three draws in [lo, hi), taken in the order x, y, z. Never write
  /// glm::vec3(rng.uniform(), rng.uniform(), ...): C++ leaves the order in
  /// which function arguments are evaluated unspecified (GCC goes right to
  /// left, Clang left to right), and the scene would differ between them.
  glm::vec2 uniform2(float lo, float hi) {
    const float x = uniform(lo, hi);
    const float y = uniform(lo, hi);
    return {x, y};
  }
  glm::vec3 uniform3(float lo, float hi) {
    const float x = uniform(lo, hi);
    const float y = uniform(lo, hi);
    const float z = uniform(lo, hi);
    return {x, y, z};
  }
  /// Uniform in [0, 1) with 53 bits.
  double uniform_double() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  /// Uniform integer in [0, n) (n > 0), by Lemire's multiply-shift; the bias
  /// (below n / 2^64) is irrelevant for scene layout.
  std::uint64_t below(std::uint64_t n) {
    return static_cast<std::uint64_t>((static_cast<unsigned __int128>(next()) * n) >> 64);
  }
  /// A random unit vector: a point of the cube [-1, 1)^3 (uniform(-1, 1) per
  /// axis, x first), kept when its length is in (0.05, 1], normalised.
  glm::vec3 unit_vector() {
    for (;;) {
      const glm::vec3 v = uniform3(-1.0f, 1.0f);
      const float l = glm::length(v);
      if (l > 0.05f && l <= 1.0f) return v / l;
    }
  }

 private:
  std::uint64_t state_;
};

/// Stateless hash of a 64-bit key (one SplitMix64 step): used where a value
/// must depend on a position or an index rather than on draw order (value
/// noise, per-ray streams that do not depend on thread scheduling).
inline std::uint64_t hash64(std::uint64_t x) { return mix64(x + kGolden64); }

}  // namespace accelviz
