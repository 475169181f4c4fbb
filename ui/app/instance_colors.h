#pragma once
// Per-instance colours of a two-level structure's view: each instance gets a
// colour hashed from its id (hash64, core/util/random.h), so it keeps its
// colour across frames, builds and runs, and neighbouring ids look unlike.
// GL-free: the 3D view uploads triangle_instance_colors() to the mesh pass
// and colours an instance's boxes with instance_color().
#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "core/scene/scene.h"
#include "core/util/random.h"

namespace accelviz {

/// The colour of instance ID: hue from 24 bits of hash64(ID), saturation in
/// [0.55, 0.85) and value in [0.75, 1) from 8 bits each (bright enough to
/// read under headlight shading, never grey).
inline glm::vec3 instance_color(std::uint32_t id) {
  const std::uint64_t h = hash64(id);
  const float hue = static_cast<float>(h >> 40) * 0x1.0p-24f;                        // [0, 1)
  const float sat = 0.55f + 0.30f * static_cast<float>((h >> 32) & 0xFFu) / 256.0f;  // [0.55, 0.85)
  const float val = 0.75f + 0.25f * static_cast<float>((h >> 24) & 0xFFu) / 256.0f;  // [0.75, 1)
  // HSV to RGB.
  const float h6 = hue * 6.0f;
  const int sector = static_cast<int>(h6) % 6;
  const float f = h6 - std::floor(h6);
  const float p = val * (1.0f - sat), q = val * (1.0f - sat * f), t = val * (1.0f - sat * (1.0f - f));
  switch (sector) {
    case 0:
      return {val, t, p};
    case 1:
      return {q, val, p};
    case 2:
      return {p, val, t};
    case 3:
      return {p, q, val};
    case 4:
      return {t, p, val};
    default:
      return {val, p, q};
  }
}

/// One colour per world triangle of SCENE (Scene::triangles): the colour of
/// the instance whose range holds it. Triangles no instance covers keep
/// `fallback`. Empty when SCENE has no world triangle list (an instanced
/// scene left unflattened draws nothing to colour).
inline std::vector<glm::vec3> triangle_instance_colors(const Scene& scene, glm::vec3 fallback = glm::vec3(0.75f)) {
  std::vector<glm::vec3> out(scene.triangles.size(), fallback);
  for (std::uint32_t i = 0; i < scene.instances.size(); ++i) {
    const Instance& inst = scene.instances[i];
    const glm::vec3 c = instance_color(i);
    const std::size_t end = std::min<std::size_t>(out.size(), std::size_t{inst.first_triangle} + inst.triangle_count);
    for (std::size_t k = inst.first_triangle; k < end; ++k) out[k] = c;
  }
  return out;
}

}  // namespace accelviz
