#pragma once
// Small scene builders and a seeded random source shared by the tests of the
// space-partitioning structures (K-D tree, grid, octree, voxels) and their
// differential test, the triangle-box overlap test and the robustness tests:
// one definition instead of one per test file.
#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

#include "core/geometry/triangle.h"

namespace accelviz::test_scenes {

/// A 64-bit LCG: the same seed gives the same scene on every platform.
struct Rng {
  std::uint64_t s;
  double next() {
    s = s * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<double>(s >> 11) * (1.0 / 9007199254740992.0);
  }
  float range(float a, float b) { return a + (b - a) * static_cast<float>(next()); }
  int below(int n) { return static_cast<int>(next() * n) % n; }
  glm::vec3 in_box(const glm::vec3& lo, const glm::vec3& hi) {
    return {range(lo.x, hi.x), range(lo.y, hi.y), range(lo.z, hi.z)};
  }
  /// A point of the cube [a, b]^3.
  glm::vec3 vec(float a, float b) { return in_box(glm::vec3(a), glm::vec3(b)); }
  /// A random unit vector (rejection sampling in the unit ball's shell).
  glm::vec3 unit() {
    for (;;) {
      const glm::vec3 v{range(-1, 1), range(-1, 1), range(-1, 1)};
      const float l = glm::length(v);
      if (l > 0.05f && l <= 1.0f) return v / l;
    }
  }
};

/// `n` random triangles of corner distance `size` from centres uniform in [lo, hi].
inline std::vector<Triangle> soup(std::uint64_t seed, int n, float size, const glm::vec3& lo = glm::vec3(-1),
                                  const glm::vec3& hi = glm::vec3(1)) {
  Rng rng{seed};
  std::vector<Triangle> s;
  for (int i = 0; i < n; ++i) {
    const glm::vec3 c = rng.in_box(lo, hi);
    s.push_back({c + size * rng.unit(), c + size * rng.unit(), c + size * rng.unit()});
  }
  return s;
}

/// Quad (a, b, c, d in order) as two triangles.
inline void quad(std::vector<Triangle>& s, glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d) {
  s.push_back({a, b, c});
  s.push_back({a, c, d});
}

/// Axis-aligned box as 12 triangles.
inline void box(std::vector<Triangle>& s, const glm::vec3& lo, const glm::vec3& hi) {
  const glm::vec3 p[8] = {{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {lo.x, hi.y, lo.z},
                          {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}};
  quad(s, p[0], p[1], p[2], p[3]);
  quad(s, p[4], p[5], p[6], p[7]);
  quad(s, p[0], p[1], p[5], p[4]);
  quad(s, p[3], p[2], p[6], p[7]);
  quad(s, p[0], p[3], p[7], p[4]);
  quad(s, p[1], p[2], p[6], p[5]);
}

// A closed axis-aligned cube [lo, lo+size]^3, each face an n x n grid of quads
// (two triangles each); grid vertices are computed once, so shared vertices
// and edges are bit-identical.
inline std::vector<Triangle> subdivided_cube(glm::vec3 lo, float size, int n) {
  std::vector<Triangle> out;
  auto coord = [&](int i) { return i == n ? size : size * static_cast<float>(i) / static_cast<float>(n); };
  for (int axis = 0; axis < 3; ++axis) {
    for (int side = 0; side < 2; ++side) {
      const int u = (axis + 1) % 3, w = (axis + 2) % 3;
      auto p = [&](int i, int j) {
        glm::vec3 q;
        q[axis] = lo[axis] + (side ? size : 0.0f);
        q[u] = lo[u] + coord(i);
        q[w] = lo[w] + coord(j);
        return q;
      };
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          out.push_back({p(i, j), p(i + 1, j), p(i + 1, j + 1)});
          out.push_back({p(i, j), p(i + 1, j + 1), p(i, j + 1)});
        }
    }
  }
  return out;
}

}  // namespace accelviz::test_scenes
