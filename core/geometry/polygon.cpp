#include "core/geometry/polygon.h"

#include <algorithm>
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

/// Flat corners one triangle of a convex face's cut takes as a fan; more keep the halving.
constexpr std::size_t kMaxFannedFlatCorners = 8;

/// A triangle (x, y, z) of the polygon's winding whose sides x→y, y→z and z→x carry the flat
/// corners FLAT[0], FLAT[1] and FLAT[2] (each in outline order, strictly between the side's ends),
/// as triangles without a zero-area one: the side with flat corners fanned from the opposite
/// corner, and the fan's first and last triangles, whose other sides are the triangle's, each
/// fanned again from the flat corner they hold over that side's flat corners. One triangle more
/// per flat corner; every outline edge is used as it is (no crack beside a neighbouring face).
/// Over kMaxFannedFlatCorners the fans' slivers would each span the triangle (boxes that overlap
/// for every structure), so such a triangle and its flat corners are halved as a convex polygon
/// (split_convex): zero-area triangles along the straight sides, each in a small box.
void fan_sides(std::array<std::uint32_t, 3> t, std::array<std::span<const std::uint32_t>, 3> flat,
               std::vector<std::array<std::uint32_t, 3>>& out) {
  const std::size_t flats = flat[0].size() + flat[1].size() + flat[2].size();
  if (flats == 0) {
    out.push_back(t);
    return;
  }
  if (flats > kMaxFannedFlatCorners) {
    std::vector<std::uint32_t> corners;  // the triangle's outline with its flat corners
    for (int s = 0; s < 3; ++s) {
      corners.push_back(t[s]);
      corners.insert(corners.end(), flat[s].begin(), flat[s].end());
    }
    const std::size_t first = out.size();
    split_convex(static_cast<std::uint32_t>(corners.size()), out);
    for (std::size_t k = first; k < out.size(); ++k)
      for (std::uint32_t& i : out[k]) i = corners[i];
    return;
  }
  while (flat[0].empty()) {  // rotate: the side x→y carries flat corners
    std::rotate(t.begin(), t.begin() + 1, t.end());
    std::rotate(flat.begin(), flat.begin() + 1, flat.end());
  }
  const auto [x, y, z] = t;
  const std::span<const std::uint32_t> f = flat[0];
  // The fan from z over x, f..., y; its first triangle (z, x, f0) holds side z→x, its last
  // (z, fk, y) side y→z: each fanned again from its flat corner when that side carries any.
  const auto over = [&](std::uint32_t apex, std::uint32_t from, std::span<const std::uint32_t> mid, std::uint32_t to) {
    std::uint32_t prev = from;
    for (const std::uint32_t q : mid) {
      out.push_back({apex, prev, q});
      prev = q;
    }
    out.push_back({apex, prev, to});
  };
  over(f.front(), z, flat[2], x);  // (z, x, f0) as (f0, z, ..., x)
  for (std::size_t k = 0; k + 1 < f.size(); ++k) out.push_back({z, f[k], f[k + 1]});
  over(f.back(), y, flat[1], z);  // (z, fk, y) as (fk, y, ..., z)
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
    // Flat corners (on the straight line from one neighbour to the other, going on: a T-junction
    // of the mesh) would make zero-area triangles in the fan or the halving; the strictly convex
    // polygon of the other corners is cut instead, and each flat corner fanned in from the
    // triangle on its side (fan_sides). A corner that turns back or repeats its neighbour keeps
    // the cut below: no triangulation of it is free of a zero-area triangle.
    std::vector<char> flat(n, 0);
    bool any_flat = false, back = false;
    for (std::size_t i = 0; i < n; ++i) {
      const glm::dvec2 &a = p[(i + n - 1) % n], &b = p[i], &c = p[(i + 1) % n];
      if (cross2(a, b, c) != 0.0) continue;
      flat[i] = glm::dot(b - a, c - b) > 0.0;
      any_flat = any_flat || flat[i];
      back = back || !flat[i];
    }
    std::vector<std::uint32_t> strict;  // the strictly convex corners, in order
    for (std::uint32_t i = 0; i < n; ++i)
      if (!flat[i]) strict.push_back(i);
    if (any_flat && !back && strict.size() >= 3) {
      const std::size_t s = strict.size();
      std::vector<std::array<std::uint32_t, 3>> cut;  // indices into `strict`
      if (s == 4) {
        std::vector<std::uint32_t> four{0, 1, 2, 3};
        fan(four, cut);
      } else if (s == 3) {
        cut.push_back({0, 1, 2});
      } else {
        split_convex(static_cast<std::uint32_t>(s), cut);
      }
      // The flat corners on the side from strict[k] to strict[k + 1]: ring(at[k], at[k + 1]), the
      // outline rotated to start at strict[0], at[k] being strict[k]'s place in it.
      std::vector<std::uint32_t> ring(n);
      for (std::size_t i = 0; i < n; ++i) ring[i] = static_cast<std::uint32_t>((strict[0] + i) % n);
      std::vector<std::size_t> at(s + 1);  // strict[k]'s position in ring
      for (std::size_t k = 0; k < s; ++k) at[k] = (strict[k] + n - strict[0]) % n;
      at[s] = n;
      const auto side = [&](std::uint32_t from, std::uint32_t to) -> std::span<const std::uint32_t> {
        if ((from + 1) % s != to) return {};  // a chord, not a side of the polygon
        return std::span<const std::uint32_t>(ring).subspan(at[from] + 1, at[from + 1] - at[from] - 1);
      };
      for (const auto& [i, j, k] : cut)
        fan_sides({strict[i], strict[j], strict[k]}, {side(i, j), side(j, k), side(k, i)}, out);
      return out;
    }
    if (n == 4)
      fan(order, out);  // a quad: the diagonal 0-2 the loaders always made
    else
      split_convex(static_cast<std::uint32_t>(n), out);
    return out;
  }
  // Ear clipping: a corner whose triangle with its neighbours turns the polygon's way and holds no
  // other remaining corner. Only reflex (or flat) corners need checking: if a corner lies in the
  // triangle of a convex one, so does a reflex one (Eberly, "Triangulation by Ear Clipping"); they
  // are kept in a grid of cells, so that an ear checks the few near it. The ring is a linked list
  // (cutting an ear is O(1)). After an ear the walk goes on past its far neighbour: a round cuts
  // every other corner of a convex stretch, the next round the halves left, so the triangles stay
  // small near the outline and fatten round by round (going back to the near neighbour made a fan
  // of slivers from one corner). A whole round without an ear (a self-intersecting outline) or a
  // spent budget of corner checks (4 n^2: no face, however shaped, takes long) leaves the rest to
  // the fan.
  std::vector<std::uint32_t> next(n), prev(n);
  for (std::size_t k = 0; k < n; ++k) {
    next[k] = static_cast<std::uint32_t>((k + 1) % n);
    prev[k] = static_cast<std::uint32_t>((k + n - 1) % n);
  }
  const auto reflex = [&](std::uint32_t b) { return cross2(p[prev[b]], p[b], p[next[b]]) <= 0.0; };
  glm::dvec2 lo = p[0], hi = p[0];
  for (const glm::dvec2& q : p) {
    lo = glm::min(lo, q);
    hi = glm::max(hi, q);
  }
  const int cells = std::max(1, static_cast<int>(std::sqrt(static_cast<double>(n) / 4.0)));  // per axis
  const glm::dvec2 extent = glm::max(hi - lo, glm::dvec2(1e-300));
  const auto cell_of = [&](double x, double lo_, double extent_) {
    const double c = std::floor((x - lo_) / extent_ * cells);
    return std::clamp(std::isfinite(c) ? static_cast<int>(c) : 0, 0, cells - 1);
  };
  std::vector<std::vector<std::uint32_t>> grid(static_cast<std::size_t>(cells) * cells);
  std::vector<char> listed(n, 0), removed(n, 0);  // listed: in its cell's list
  const auto list = [&](std::uint32_t q) {
    if (listed[q] || !reflex(q)) return;
    listed[q] = 1;
    grid[static_cast<std::size_t>(cell_of(p[q].y, lo.y, extent.y)) * cells + cell_of(p[q].x, lo.x, extent.x)].push_back(
        q);
  };
  for (std::uint32_t k = 0; k < n; ++k) list(k);
  std::size_t r = n, checks = 0, since_ear = 0;
  std::uint32_t b = 0;
  const std::size_t budget = 4 * n * n;
  while (r > 3 && since_ear < r && checks < budget) {
    const std::uint32_t a = prev[b], c = next[b];
    bool ear = cross2(p[a], p[b], p[c]) > 0.0;  // reflex or flat: no ear
    if (ear) {
      const glm::dvec2 e_lo = glm::min(p[a], glm::min(p[b], p[c])), e_hi = glm::max(p[a], glm::max(p[b], p[c]));
      const int x0 = cell_of(e_lo.x, lo.x, extent.x), x1 = cell_of(e_hi.x, lo.x, extent.x);
      const int y0 = cell_of(e_lo.y, lo.y, extent.y), y1 = cell_of(e_hi.y, lo.y, extent.y);
      for (int y = y0; y <= y1 && ear; ++y)
        for (int x = x0; x <= x1 && ear; ++x) {
          std::vector<std::uint32_t>& in_cell = grid[static_cast<std::size_t>(y) * cells + x];
          for (std::size_t k = 0; k < in_cell.size() && ear;) {
            ++checks;
            const std::uint32_t q = in_cell[k];
            if (removed[q] || !reflex(q)) {  // cut, or convex now: off the list (swap with the last)
              listed[q] = 0;
              in_cell[k] = in_cell.back();
              in_cell.pop_back();
              continue;
            }
            ++k;
            if (q == a || q == b || q == c || p[q] == p[a] || p[q] == p[b] || p[q] == p[c]) continue;
            ear = !(cross2(p[a], p[b], p[q]) >= 0.0 && cross2(p[b], p[c], p[q]) >= 0.0 &&
                    cross2(p[c], p[a], p[q]) >= 0.0);
          }
        }
    }
    if (!ear) {
      b = c;
      ++since_ear;
      continue;
    }
    out.push_back({a, b, c});
    removed[b] = 1;
    next[a] = c;
    prev[c] = a;
    --r;
    since_ear = 0;
    list(a);  // their angles changed
    list(c);
    b = next[c];
  }
  std::vector<std::uint32_t> rest;
  rest.reserve(r);
  for (std::size_t k = 0; k < r; ++k, b = next[b]) rest.push_back(b);
  fan(rest, out);
  return out;
}

}  // namespace accelviz
