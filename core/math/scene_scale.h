#pragma once
// Rays made at a scene's own scale (verify's and the robustness lab's
// adversarial rays): unit directions scaled by a power of two near the
// scene's size, and the check that a made direction is one a ray can take.
#include <cmath>

#include <glm/glm.hpp>

namespace accelviz {

/// The power of two at or below `s` (> 0, finite). A unit direction scaled
/// by it is aimed exactly as before (scaling by a power of two rounds
/// nothing) while its t is on the scene's scale, as for rays aimed at a
/// point (t = 1 there): tolerances of the form 1e-6·max(1, t) then mean the
/// same at every scale.
inline float power_of_two_at_or_below(float s) {
  int e = 0;
  std::frexp(s, &e);
  return std::ldexp(1.0f, e - 1);
}

/// Finite and not zero, judged by components (|d|² underflows at 1e-23 and
/// overflows at 1e19).
inline bool usable_direction(const glm::vec3& d) {
  return std::isfinite(d.x) && std::isfinite(d.y) && std::isfinite(d.z) && (d.x != 0.0f || d.y != 0.0f || d.z != 0.0f);
}

}  // namespace accelviz
