#pragma once
// The surface hit record shared by every primitive test and structure.
#include "core/math/ray.h"

#include <glm/glm.hpp>

#include <cstdint>

namespace accelviz {

struct Hit {
  std::uint32_t prim = kInvalidId;  ///< primitive id in scene load order; kInvalidId = miss
  float t = kInfinity;              ///< ray parameter of the hit
  float u = 0.0f, v = 0.0f;         ///< barycentrics: p = (1-u-v)·v0 + u·v1 + v·v2
  glm::vec3 ng{0.0f};               ///< geometric normal (unit length, not flipped toward the ray)
  std::uint32_t instance = kInvalidId;  ///< instance hit, for two-level structures

  bool valid() const { return prim != kInvalidId; }
};

}  // namespace accelviz
