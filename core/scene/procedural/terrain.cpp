// builtin:terrain — a height field: a regular grid of small, well-shaped,
// nearly horizontal triangles, the friendly case for every structure (and
// the classic case for 2D grids and quadtrees over the ground plane).
// Heights are fractional Brownian motion over value noise (Perlin 1985;
// Musgrave's fBm as in Ebert et al., "Texturing and Modeling", 2003).
#include "core/scene/procedural/reproducible_fp.h"  // first: see there

#include "core/scene/procedural/common.h"
#include "core/scene/procedural/generators.h"
#include "core/scene/procedural/random.h"

#include <algorithm>
#include <cmath>

namespace accelviz::procedural {

namespace {

constexpr double kExtent = 100.0;      // the terrain covers [-50, 50]^2 in x/z
constexpr double kAmplitude = 12.0;    // first octave's height amplitude
constexpr double kBaseFrequency = 0.04;  // lattice cells per unit at octave 0 (4 across)
constexpr int kOctaves = 6;

/// Lattice value in [-1, 1] at integer point (ix, iz) of octave OCTAVE: a hash
/// of position and seed, so it does not depend on evaluation order.
double lattice(std::uint64_t seed, std::int64_t ix, std::int64_t iz, int octave) {
  std::uint64_t h = hash64(seed);
  h = hash64(h ^ static_cast<std::uint64_t>(ix));
  h = hash64(h ^ (static_cast<std::uint64_t>(iz) + (static_cast<std::uint64_t>(octave) << 48)));
  return static_cast<double>(h >> 11) * 0x1.0p-52 - 1.0;
}

/// Value noise: bilinear interpolation of lattice values with smoothstep
/// weights (continuous slopes across cells). u, v >= 0.
double value_noise(std::uint64_t seed, double u, double v, int octave) {
  const double fu = std::floor(u), fv = std::floor(v);
  const auto iu = static_cast<std::int64_t>(fu);
  const auto iv = static_cast<std::int64_t>(fv);
  const double tu = u - fu, tv = v - fv;
  const double su = tu * tu * (3.0 - 2.0 * tu);
  const double sv = tv * tv * (3.0 - 2.0 * tv);
  const double a = lattice(seed, iu, iv, octave), b = lattice(seed, iu + 1, iv, octave);
  const double c = lattice(seed, iu, iv + 1, octave), d = lattice(seed, iu + 1, iv + 1, octave);
  return (a + (b - a) * su) + ((c + (d - c) * su) - (a + (b - a) * su)) * sv;
}

/// fBm: octaves of doubling frequency and halving amplitude.
double height_at(std::uint64_t seed, double x, double z) {
  double sum = 0.0, amplitude = kAmplitude, frequency = kBaseFrequency;
  for (int o = 0; o < kOctaves; ++o) {
    // Shift so that lattice coordinates are non-negative.
    sum += amplitude * value_noise(seed, (x + 0.5 * kExtent) * frequency, (z + 0.5 * kExtent) * frequency, o);
    amplitude *= 0.5;
    frequency *= 2.0;
  }
  return sum;
}

}  // namespace

Scene make_terrain(const BuiltinArgs& args) {
  // n x n quads, two triangles each.
  const std::int64_t n =
      std::max<std::int64_t>(1, std::llround(std::sqrt(static_cast<double>(args.size) / 2.0)));
  const std::int64_t side = n + 1;

  Mesh mesh;
  mesh.name = "terrain";
  mesh.positions.reserve(static_cast<std::size_t>(side * side));
  mesh.indices.reserve(static_cast<std::size_t>(2 * n * n));
  for (std::int64_t i = 0; i <= n; ++i) {
    const double x = -0.5 * kExtent + kExtent * static_cast<double>(i) / static_cast<double>(n);
    for (std::int64_t j = 0; j <= n; ++j) {
      const double z = -0.5 * kExtent + kExtent * static_cast<double>(j) / static_cast<double>(n);
      mesh.positions.emplace_back(static_cast<float>(x), static_cast<float>(height_at(args.seed, x, z)),
                                  static_cast<float>(z));
    }
  }
  for (std::int64_t i = 0; i < n; ++i) {
    for (std::int64_t j = 0; j < n; ++j) {
      const auto a = static_cast<std::uint32_t>(i * side + j);
      const auto b = static_cast<std::uint32_t>(i * side + j + 1);
      const auto c = static_cast<std::uint32_t>((i + 1) * side + j + 1);
      const auto d = static_cast<std::uint32_t>((i + 1) * side + j);
      // (i,j) -> (i,j+1) -> (i+1,j+1): z x x = +y, facing up.
      mesh.indices.emplace_back(a, b, c);
      mesh.indices.emplace_back(a, c, d);
    }
  }

  Scene scene;
  const Aabb box = mesh_bounds(mesh);
  place_mesh(scene, add_mesh(scene, std::move(mesh)), "terrain");
  scene.cameras.push_back(frame_box("overview", box, glm::vec3(0.6f, 0.55f, 1.0f)));
  scene.lights.push_back(directional_light("sun", glm::vec3(-0.5f, -0.8f, -0.2f), 3.0f));
  finish(scene, args);
  return scene;
}

}  // namespace accelviz::procedural
