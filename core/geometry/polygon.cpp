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

/// The reflex (and flat) corners of a polygon being ear-clipped, in rows of equal height and, within
/// a row, sorted by x, so that an ear's test looks only at the corners in the x range its triangle
/// spans in each row it crosses. A corner that turns convex leaves at once: its place is skipped by
/// a union-find over the places (path halving), so a row's corners cut or turned convex are never
/// walked again (the grid of cells this replaces kept them until met, and a comb's spine, a line of
/// 50,000 flat corners, filled a few cells). A corner that rounding turns reflex after the start
/// (exactly, a convex corner stays convex as ears are cut) goes to a short list checked by every ear.
class ReflexRows {
 public:
  ReflexRows(std::span<const glm::dvec2> p, std::span<const std::uint32_t> reflex) : p_(p), place_(p.size(), kNone) {
    if (reflex.empty()) return;
    double hi = p_[reflex[0]].y;
    lo_ = hi;
    for (const std::uint32_t q : reflex) {
      lo_ = std::min(lo_, p_[q].y);
      hi = std::max(hi, p_[q].y);
    }
    height_ = std::max(hi - lo_, 1e-300);
    rows_ = std::max(1, static_cast<int>(std::sqrt(static_cast<double>(reflex.size()) / 4.0)));
    order_.assign(reflex.begin(), reflex.end());
    std::sort(order_.begin(), order_.end(), [&](std::uint32_t u, std::uint32_t v) {
      const int ru = row_of(p_[u].y), rv = row_of(p_[v].y);
      return ru != rv ? ru < rv : p_[u].x != p_[v].x ? p_[u].x < p_[v].x : u < v;
    });
    start_.assign(static_cast<std::size_t>(rows_) + 1, 0);
    for (const std::uint32_t q : order_) ++start_[static_cast<std::size_t>(row_of(p_[q].y)) + 1];
    for (int r = 0; r < rows_; ++r) start_[r + 1] += start_[r];
    xs_.resize(order_.size());
    skip_.resize(order_.size() + 1);
    for (std::uint32_t i = 0; i < order_.size(); ++i) {
      xs_[i] = p_[order_[i]].x;
      skip_[i] = i;
      place_[order_[i]] = i;
    }
    skip_[order_.size()] = static_cast<std::uint32_t>(order_.size());
  }

  /// A corner's angle changed: out when it is no longer reflex; in the late list when it turned reflex.
  void update(std::uint32_t q, bool reflex) {
    if (!reflex && place_[q] != kNone) {
      skip_[place_[q]] = place_[q] + 1;
      place_[q] = kNone;
    } else if (!reflex) {
      late_.erase(std::remove(late_.begin(), late_.end(), q), late_.end());
    } else if (place_[q] == kNone && std::find(late_.begin(), late_.end(), q) == late_.end()) {
      late_.push_back(q);
    }
  }

  /// Whether `inside` holds for a corner listed near the triangle (a, b, c): every listed corner in
  /// or on the triangle is offered (some outside it too), until one answers true.
  template <class Inside>
  bool any_in_triangle(std::uint32_t a, std::uint32_t b, std::uint32_t c, Inside&& inside) {
    for (const std::uint32_t q : late_)
      if (inside(q)) return true;
    if (order_.empty()) return false;
    const glm::dvec2 &pa = p_[a], &pb = p_[b], &pc = p_[c];
    const double y_lo = std::min({pa.y, pb.y, pc.y}), y_hi = std::max({pa.y, pb.y, pc.y});
    const double x_lo = std::min({pa.x, pb.x, pc.x}), x_hi = std::max({pa.x, pb.x, pc.x});
    const double margin = 1e-9 * (x_hi - x_lo) + 1e-300;
    for (int row = row_of(y_lo), last = row_of(y_hi); row <= last; ++row) {
      // The triangle's x range in the row's band: its edges clipped to the band, whose ends are
      // where the range's ends lie. The band a thousandth of a row wider on each side, and the
      // range a little wider, so that rounding never leaves out a corner the triangle touches.
      const double band_lo = lo_ + height_ * (row - 1e-3) / rows_, band_hi = lo_ + height_ * (row + 1 + 1e-3) / rows_;
      double from = x_hi, to = x_lo;
      for (const auto& [s, t] : {std::pair{&pa, &pb}, std::pair{&pb, &pc}, std::pair{&pc, &pa}}) {
        const double ylo = std::max(std::min(s->y, t->y), band_lo), yhi = std::min(std::max(s->y, t->y), band_hi);
        if (ylo > yhi) continue;
        if (s->y == t->y) {
          from = std::min({from, s->x, t->x});
          to = std::max({to, s->x, t->x});
          continue;
        }
        for (const double y : {ylo, yhi}) {
          const double x = s->x + (t->x - s->x) * ((y - s->y) / (t->y - s->y));
          from = std::min(from, x);
          to = std::max(to, x);
        }
      }
      from = std::max(from, x_lo) - margin;
      to = std::min(to, x_hi) + margin;
      if (from > to) continue;
      const std::uint32_t end = start_[row + 1];
      auto i = static_cast<std::uint32_t>(std::lower_bound(xs_.begin() + start_[row], xs_.begin() + end, from) -
                                          xs_.begin());
      for (i = alive(i); i < end && xs_[i] <= to; i = alive(i + 1))
        if (inside(order_[i])) return true;
    }
    return false;
  }

 private:
  static constexpr std::uint32_t kNone = ~std::uint32_t{0};

  /// Clamped in double before the cast: the bounds are the reflex corners', and an ear's corner may
  /// lie far outside them (a float-to-int cast out of range is undefined; the fuzzer found one).
  int row_of(double y) const {
    const double r = std::floor((y - lo_) / height_ * rows_);
    return r >= 0.0 ? static_cast<int>(std::min(r, static_cast<double>(rows_ - 1))) : 0;  // NaN: 0
  }

  /// The first place at or after i whose corner is still listed (order_.size() when none).
  std::uint32_t alive(std::uint32_t i) {
    while (skip_[i] != i) {
      skip_[i] = skip_[skip_[i]];
      i = skip_[i];
    }
    return i;
  }

  std::span<const glm::dvec2> p_;
  double lo_ = 0.0, height_ = 1.0;
  int rows_ = 1;
  std::vector<std::uint32_t> order_;  ///< the listed corners by row, then x
  std::vector<double> xs_;            ///< their x, for the search
  std::vector<std::uint32_t> start_;  ///< each row's first place in order_; rows_ + 1 entries
  std::vector<std::uint32_t> skip_;   ///< union-find: a place, or one nearer the next listed place
  std::vector<std::uint32_t> place_;  ///< each corner's place in order_, or kNone
  std::vector<std::uint32_t> late_;   ///< corners turned reflex by rounding after the start
};

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
  // are kept by rows and x (ReflexRows), so that an ear checks the few its triangle spans. The
  // ring is a linked list (cutting an ear is O(1)). After an ear the walk goes on past its far
  // neighbour: a round cuts every other corner of a convex stretch, the next round the halves
  // left, so the triangles stay small near the outline and fatten round by round (going back to
  // the near neighbour made a fan of slivers from one corner).
  //
  // The walk visits only the candidates: corners not yet found to be no ear since their
  // neighbours last changed (a second linked list in ring order). Cutting an ear changes only its
  // neighbours' triangles, and the corners left only lose reflex corners, and by the same lemma a
  // corner whose triangle held one still holds one; so a corner found to be no ear stays no ear
  // until a neighbour of it is cut, and it is dropped from the walk until then. Walking every
  // corner round after round was quadratic where each round cuts only a few ears (a comb's spine,
  // a zig-zag strip, a spiral band: 100,000 corners took 5-16 s). When the candidates run out with
  // corners left, every corner left is walked once more (a self-intersecting outline breaks the
  // lemma); a whole round without an ear, or a spent budget of corner checks (4 n^2: no face,
  // however shaped, takes long), leaves the rest to the fan.
  std::vector<std::uint32_t> next(n), prev(n);
  for (std::size_t k = 0; k < n; ++k) {
    next[k] = static_cast<std::uint32_t>((k + 1) % n);
    prev[k] = static_cast<std::uint32_t>((k + n - 1) % n);
  }
  std::vector<std::uint32_t> cnext(next), cprev(prev);  // the candidates' ring
  std::vector<char> candidate(n, 1);
  std::size_t candidates = n;
  const auto leave_walk = [&](std::uint32_t q) {
    candidate[q] = 0;
    cnext[cprev[q]] = cnext[q];
    cprev[cnext[q]] = cprev[q];
    --candidates;
  };
  const auto insert_before = [&](std::uint32_t q, std::uint32_t at) {
    candidate[q] = 1;
    cprev[q] = cprev[at];
    cnext[q] = at;
    cnext[cprev[at]] = q;
    cprev[at] = q;
    ++candidates;
  };
  const auto reflex = [&](std::uint32_t b) { return cross2(p[prev[b]], p[b], p[next[b]]) <= 0.0; };
  std::vector<std::uint32_t> reflex_corners;
  for (std::uint32_t k = 0; k < n; ++k)
    if (reflex(k)) reflex_corners.push_back(k);
  ReflexRows rows(p, reflex_corners);
  std::size_t r = n, checks = 0;
  std::uint32_t b = 0;
  bool walked_again = false;  // every corner left made a candidate again, and no ear since
  const std::size_t budget = 4 * n * n;
  while (r > 3 && checks < budget) {
    if (candidates == 0) {
      if (walked_again) break;  // a whole round without an ear
      walked_again = true;
      for (std::size_t k = 0; k < r; ++k, b = next[b]) {
        candidate[b] = 1;
        cnext[b] = next[b];
        cprev[b] = prev[b];
      }
      candidates = r;
    }
    const std::uint32_t a = prev[b], c = next[b];
    bool ear = cross2(p[a], p[b], p[c]) > 0.0;  // reflex or flat: no ear
    if (ear)
      ear = !rows.any_in_triangle(a, b, c, [&](std::uint32_t q) {
        ++checks;
        if (q == a || q == b || q == c || p[q] == p[a] || p[q] == p[b] || p[q] == p[c]) return false;
        return cross2(p[a], p[b], p[q]) >= 0.0 && cross2(p[b], p[c], p[q]) >= 0.0 && cross2(p[c], p[a], p[q]) >= 0.0;
      });
    if (!ear) {
      const std::uint32_t after = cnext[b];
      leave_walk(b);
      b = after;
      continue;
    }
    out.push_back({a, b, c});
    next[a] = c;
    prev[c] = a;
    --r;
    walked_again = false;
    // Their triangles changed: candidates again, in ring order around b (a just before it, c just
    // after), before b leaves the candidates' ring.
    if (!candidate[a]) insert_before(a, b);
    if (!candidate[c]) insert_before(c, cnext[b]);
    leave_walk(b);
    for (const std::uint32_t q : {a, c}) rows.update(q, reflex(q));  // their angles changed
    b = cnext[c];
  }
  std::vector<std::uint32_t> rest;
  rest.reserve(r);
  for (std::size_t k = 0; k < r; ++k, b = next[b]) rest.push_back(b);
  fan(rest, out);
  return out;
}

}  // namespace accelviz
