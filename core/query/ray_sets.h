#pragma once
// The ray sets the benchmark, the ray-file generator and the heatmaps use:
// primary (coherent camera rays), diffuse (incoherent cosine-weighted bounces
// from the primary hits) and shadow (hit points towards the lights). All are
// deterministic functions of their inputs and the seed, whatever the thread count.
#include "core/accel/accel.h"
#include "core/scene/scene.h"

#include <cstdint>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

namespace accelviz {

enum class RayKind { primary, diffuse, shadow };

std::string_view ray_kind_name(RayKind kind);
std::optional<RayKind> parse_ray_kind(std::string_view name);

/// One camera ray per pixel of a W×H image, row by row from the top-left
/// (index = y·W + x), through pixel centres.
std::vector<Ray> primary_rays(const Camera& cam, int width, int height);

/// Hit point of a closest hit on its triangle, from the barycentrics (more
/// accurate than origin + t·direction far from the origin).
glm::vec3 hit_point(std::span<const Triangle> triangles, const Hit& hit);

/// For every primary ray that hit something (in order), one bounce ray from
/// the hit point into the hemisphere on the side the ray came from, with a
/// cosine-weighted direction (Malley's method). The origin is offset with
/// offset_ray_origin so the bounce does not re-hit its own surface. Ray i's
/// random numbers depend only on (seed, i).
std::vector<Ray> diffuse_rays(std::span<const Triangle> triangles, std::span<const Ray> primary,
                              std::span<const Hit> hits, std::uint64_t seed);

/// For every primary hit (in order) and every light (in order), a shadow ray
/// from the offset hit point towards the light: point and spot lights end
/// just short of the light's position, directional lights are unbounded.
/// Lights behind the surface (as seen from the incoming ray) get no ray: they
/// cannot light the point, and a renderer would not trace them.
std::vector<Ray> shadow_rays(std::span<const Triangle> triangles, std::span<const Ray> primary,
                             std::span<const Hit> hits, std::span<const Light> lights);

}  // namespace accelviz
