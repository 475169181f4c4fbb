#include "core/geometry/polygon.h"

#include <cmath>
#include <glm/geometric.hpp>
#include <glm/vec2.hpp>

namespace accelviz {

namespace {

double cross2(const glm::dvec2& a, const glm::dvec2& b, const glm::dvec2& c) {
  return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

void fan(std::span<const std::uint32_t> rest, std::vector<std::array<std::uint32_t, 3>>& out) {
  for (std::size_t k = 1; k + 1 < rest.size(); ++k) out.push_back({rest[0], rest[k], rest[k + 1]});
}

/// A convex polygon of n corners cut by the triangle (0, t, 2t), t = (n+1)/3, then each of the three
/// arcs left (a chain of corners closed by its chord) by (first, middle, last) and its halves the
/// same way: a fan of n corners makes n − 2 slivers from one corner across the whole face (a
/// 10,000-gon's fan cost the K-D tree minutes of duplicated references); this makes the large
/// triangles few (log n levels) and the rest small near the outline. Iterative: no deep recursion.
void split_convex(std::uint32_t n, std::vector<std::array<std::uint32_t, 3>>& out) {
  const std::uint32_t t = (n + 1) / 3;
  out.push_back({0, t, 2 * t});
  // Chains as [first, last] with last <= n, corner n being corner 0 again.
  std::vector<std::array<std::uint32_t, 2>> chains{{2 * t, n}, {t, 2 * t}, {0, t}};
  while (!chains.empty()) {
    const auto [a, b] = chains.back();
    chains.pop_back();
    if (b - a < 2) continue;
    const std::uint32_t m = a + (b - a) / 2;
    out.push_back({a, m, b % n});
    chains.push_back({m, b});
    chains.push_back({a, m});
  }
}

}  // namespace

std::vector<std::array<std::uint32_t, 3>> triangulate_polygon(std::span<const glm::vec3> corners) {
  const std::size_t n = corners.size();
  std::vector<std::array<std::uint32_t, 3>> out;
  if (n < 3) return out;
  out.reserve(n - 2);
  std::vector<std::uint32_t> order(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = static_cast<std::uint32_t>(i);
  // The plane: Newell's normal, robust for any simple polygon.
  glm::dvec3 normal(0.0);
  for (std::size_t i = 0; i < n; ++i) {
    const glm::dvec3 a(corners[i]), b(corners[(i + 1) % n]);
    normal += glm::dvec3((a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y));
  }
  const glm::dvec3 m = glm::abs(normal);
  if (n == 3 || !(m.x + m.y + m.z > 0.0) || !std::isfinite(m.x + m.y + m.z)) {
    fan(order, out);
    return out;
  }
  // Project onto the plane of the two other axes, counter-clockwise seen along the normal.
  const int drop = m.x >= m.y && m.x >= m.z ? 0 : m.y >= m.z ? 1 : 2;
  const int u = (drop + 1) % 3, v = (drop + 2) % 3;
  const double side = normal[drop] > 0.0 ? 1.0 : -1.0;
  std::vector<glm::dvec2> p(n);
  for (std::size_t i = 0; i < n; ++i) p[i] = {corners[i][u], side * corners[i][v]};
  bool convex = true;
  for (std::size_t i = 0; i < n && convex; ++i) convex = cross2(p[i], p[(i + 1) % n], p[(i + 2) % n]) >= 0.0;
  if (convex) {
    if (n == 4)
      fan(order, out);  // a quad: the diagonal 0-2 the loaders always made
    else
      split_convex(static_cast<std::uint32_t>(n), out);
    return out;
  }
  // Ear clipping: a corner whose triangle with its neighbours turns the polygon's way and holds no
  // other remaining corner.
  // Walks around the ring from where the last ear was cut; a whole round without an ear (a
  // self-intersecting outline) or a spent budget of corner checks (4 n^2: no face, however shaped,
  // takes long) leaves the rest to the fan.
  std::vector<std::uint32_t> rest = order;
  std::size_t checks = 0, i = 0, since_ear = 0;
  const std::size_t budget = 4 * n * n;
  while (rest.size() > 3 && since_ear < rest.size() && checks < budget) {
    const std::size_t r = rest.size();
    i %= r;
    const std::uint32_t a = rest[(i + r - 1) % r], b = rest[i], c = rest[(i + 1) % r];
    bool ear = cross2(p[a], p[b], p[c]) > 0.0;  // reflex or flat: no ear
    for (std::size_t k = 0; k < r && ear; ++k) {
      ++checks;
      const std::uint32_t q = rest[k];
      if (q == a || q == b || q == c || p[q] == p[a] || p[q] == p[b] || p[q] == p[c]) continue;
      ear = !(cross2(p[a], p[b], p[q]) >= 0.0 && cross2(p[b], p[c], p[q]) >= 0.0 && cross2(p[c], p[a], p[q]) >= 0.0);
    }
    if (!ear) {
      ++i;
      ++since_ear;
      continue;
    }
    out.push_back({a, b, c});
    rest.erase(rest.begin() + static_cast<std::ptrdiff_t>(i));
    since_ear = 0;
    if (i > 0) --i;  // the previous corner may have become an ear
  }
  fan(rest, out);
  return out;
}

}  // namespace accelviz
