#include "core/query/ray_sets.h"

#include <cmath>

#include "core/geometry/shapes.h"
#include "core/query/camera.h"
#include "core/util/parallel.h"
#include "core/util/random.h"

namespace accelviz {

namespace {

constexpr float kTwoPi = 6.28318530717959f;

/// hash64 (core/util/random.h) as a counter-based hash: ray i's numbers come
/// from hashing (seed, i, k), so the result never depends on which thread
/// traced what or in what order.

/// Uniform float in [0, 1) from the top 24 bits.
float uniform01(std::uint64_t seed, std::uint64_t index, std::uint64_t k) {
  const std::uint64_t h = hash64(hash64(seed ^ hash64(index)) + k);
  return static_cast<float>(h >> 40) * (1.0f / 16777216.0f);
}

/// An orthonormal basis around unit n (Duff et al., "Building an Orthonormal
/// Basis, Revisited", JCGT 2017).
void basis(const glm::vec3& n, glm::vec3& t, glm::vec3& b) {
  const float sign = std::copysign(1.0f, n.z);
  const float a = -1.0f / (sign + n.z);
  const float c = n.x * n.y * a;
  t = glm::vec3(1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x);
  b = glm::vec3(c, sign + n.y * n.y * a, -n.y);
}

/// Unit geometric normal facing the side the ray came from.
glm::vec3 facing_normal(std::span<const Triangle> triangles, const Ray& ray, const Hit& hit) {
  glm::vec3 n = hit.ng;
  if (glm::dot(n, n) == 0.0f) n = triangle_normal(triangles[hit.prim]);
  return glm::dot(n, ray.direction) > 0.0f ? -n : n;
}

}  // namespace

std::string_view ray_kind_name(RayKind kind) {
  switch (kind) {
    case RayKind::primary:
      return "primary";
    case RayKind::diffuse:
      return "diffuse";
    case RayKind::shadow:
      return "shadow";
  }
  return "primary";
}

std::optional<RayKind> parse_ray_kind(std::string_view name) {
  for (RayKind k : {RayKind::primary, RayKind::diffuse, RayKind::shadow})
    if (ray_kind_name(k) == name) return k;
  return std::nullopt;
}

std::vector<Ray> primary_rays(const Camera& cam, int width, int height) {
  std::vector<Ray> rays;
  if (width <= 0 || height <= 0) return rays;
  const auto w = static_cast<std::size_t>(width);
  rays.resize(w * static_cast<std::size_t>(height));
  // Rows on all threads: each ray depends on its pixel alone.
  parallel_for(static_cast<std::size_t>(height), 0, 8, [&](std::size_t y0, std::size_t y1, unsigned) {
    for (std::size_t y = y0; y < y1; ++y)
      for (int x = 0; x < width; ++x)
        rays[y * w + static_cast<std::size_t>(x)] = primary_ray(cam, x, static_cast<int>(y), width, height);
  });
  return rays;
}

glm::vec3 hit_point(std::span<const Triangle> triangles, const Hit& hit) {
  const Triangle& tri = triangles[hit.prim];
  return (1.0f - hit.u - hit.v) * tri.v0 + hit.u * tri.v1 + hit.v * tri.v2;
}

std::vector<Ray> diffuse_rays(std::span<const Triangle> triangles, std::span<const Ray> primary,
                              std::span<const Hit> hits, std::uint64_t seed) {
  std::vector<Ray> rays;
  for (std::size_t i = 0; i < hits.size() && i < primary.size(); ++i) {
    const Hit& h = hits[i];
    if (!h.valid() || h.prim >= triangles.size()) continue;
    const glm::vec3 n = facing_normal(triangles, primary[i], h);
    if (glm::dot(n, n) == 0.0f) continue;  // degenerate triangle: no hemisphere
    // Malley's method: a uniform point on the unit disk lifted to the hemisphere
    // gives a cosine-weighted direction.
    const float u1 = uniform01(seed, i, 0), u2 = uniform01(seed, i, 1);
    const float r = std::sqrt(u1), phi = kTwoPi * u2;
    const float lx = r * std::cos(phi), ly = r * std::sin(phi);
    const float lz = std::sqrt(std::max(0.0f, 1.0f - u1));
    glm::vec3 t, b;
    basis(n, t, b);
    const glm::vec3 dir = glm::normalize(lx * t + ly * b + lz * n);
    rays.emplace_back(offset_ray_origin(hit_point(triangles, h), n, coordinate_scale(triangles[h.prim])), dir, 0.0f,
                      kInfinity);
  }
  return rays;
}

std::vector<Ray> shadow_rays(std::span<const Triangle> triangles, std::span<const Ray> primary,
                             std::span<const Hit> hits, std::span<const Light> lights) {
  // Stop a little short of a positional light so that geometry modelling the
  // lamp itself does not count as a blocker.
  constexpr float kShortOfLight = 1.0f - 1e-4f;
  std::vector<Ray> rays;
  for (std::size_t i = 0; i < hits.size() && i < primary.size(); ++i) {
    const Hit& h = hits[i];
    if (!h.valid() || h.prim >= triangles.size()) continue;
    const glm::vec3 n = facing_normal(triangles, primary[i], h);
    if (glm::dot(n, n) == 0.0f) continue;
    const glm::vec3 p = offset_ray_origin(hit_point(triangles, h), n, coordinate_scale(triangles[h.prim]));
    for (const Light& light : lights) {
      glm::vec3 dir;
      float tmax = kInfinity;
      if (light.kind == Light::Kind::directional) {
        dir = -light.direction;
        const float len = glm::length(dir);
        if (!(len > 0.0f)) continue;
        dir /= len;
      } else {
        // In double: a light beyond about 1.8e19 squared its distance past float's range, and its
        // shadow rays were dropped (0 rays) as if the light were at infinity.
        const glm::dvec3 d = glm::dvec3(light.position) - glm::dvec3(p);
        const double dist = glm::length(d);
        if (!(dist > 0.0) || !std::isfinite(dist) || !(static_cast<float>(dist) < kInfinity)) continue;
        dir = glm::vec3(d / dist);
        tmax = static_cast<float>(dist) * kShortOfLight;
      }
      if (glm::dot(dir, n) <= 0.0f) continue;  // light behind the surface
      rays.emplace_back(p, dir, 0.0f, tmax);
    }
  }
  return rays;
}

}  // namespace accelviz
