// Uniform grid traversal: the 3D-DDA of Amanatides & Woo (1987), with the
// next boundary distances recomputed from the cell index at every step
// (instead of accumulated by adding t_delta) so that rounding does not
// drift along long rays.
#include <algorithm>
#include <type_traits>

#include "core/accel/grid/grid.h"
#include "core/accel/kdtree/spatial_traversal.h"

namespace accelviz {

template <bool kCollect, bool kAnyHit>
Hit Grid::traverse(const Ray& ray, const QueryOptions& qo, RayStats* stats, VisitTrace* trace) const {
  if (cell_start_.empty() || !spatial::is_traversable(ray)) return Hit{};

  // 1. Clip the ray to the grid's box (robust slab test); the ray may start
  //    inside or outside.
  SlabInterval iv;
  const bool in_box = intersect_slab(bounds_, ray, iv);
  spatial::record_root_test<kCollect>(in_box, iv.t_entry, iv.t_exit, stats, trace);
  if (!in_box) return Hit{};
  const float t_end = iv.t_exit;

  // 2. Starting cell, step direction and the distance to the next boundary
  //    per axis. An axis with a ±0 direction component (inverse infinite) or
  //    a single cell is never stepped along: its next boundary is at +inf.
  //    The entry point in double, from the slab distances in double: the float entry t of a far
  //    origin (3e7 away) is rounded by whole units, which put the entry point, and the first cell,
  //    cells away (at the grid's far side: every ray from there missed).
  //    On the axis whose face the ray enters through, the entry coordinate is that face itself:
  //    o + t·d, in double too, lost it from 1e16 away (double's spacing there is 2).
  double t0 = ray.tmin;
  int face_axis = -1;
  float face = 0.0f;
  for (int a = 0; a < 3; ++a)
    if (ray.direction[a] != 0.0f) {
      const double lo = (static_cast<double>(bounds_.lo[a]) - ray.origin[a]) / ray.direction[a];
      const double hi = (static_cast<double>(bounds_.hi[a]) - ray.origin[a]) / ray.direction[a];
      if (std::min(lo, hi) > t0) {
        t0 = std::min(lo, hi);
        face_axis = a;
        face = ray.direction[a] > 0.0f ? bounds_.lo[a] : bounds_.hi[a];  // not by the t's: they may round equal
      }
    }
  glm::dvec3 entry = glm::dvec3(ray.origin) + t0 * glm::dvec3(ray.direction);
  if (face_axis >= 0) entry[face_axis] = face;
  int idx[3], step[3];
  float t_next[3];
  for (int a = 0; a < 3; ++a) {
    idx[a] = cell_of(static_cast<float>(entry[a]), a);
    if (std::isinf(ray.inv_dir[a]) || res_[a] == 1) {
      step[a] = 0;
      t_next[a] = kInfinity;
    } else {
      step[a] = ray.inv_dir[a] > 0.0f ? 1 : -1;
      t_next[a] = (plane(a, idx[a] + (step[a] > 0)) - ray.origin[a]) * ray.inv_dir[a];
    }
  }

  spatial::CellPrimTests<kCollect, kAnyHit> prims(ray, qo.triangle_test, opts_.mailboxing, tris_, stats, trace);
  [[maybe_unused]] float t_cell = iv.t_entry;

  for (;;) {
    // 3. The current cell covers [t_cell, t_exit] of the ray.
    const float t_exit = std::min(std::min(t_next[0], t_next[1]), std::min(t_next[2], t_end));
    const std::size_t cell = static_cast<std::size_t>(idx[0]) +
                             static_cast<std::size_t>(res_[0]) * (idx[1] + static_cast<std::size_t>(res_[1]) * idx[2]);
    const std::uint32_t begin = cell_start_[cell], end = cell_start_[cell + 1];
    if constexpr (kCollect) {
      if (stats) {
        ++stats->nodes_visited;
        if (begin == end) ++stats->empty_cells;
      }
      if (trace)
        trace->steps.push_back({VisitStep::Kind::node_entered, static_cast<std::uint32_t>(cell), t_cell, t_exit});
    }
    if (prims.test(refs_.data() + begin, end - begin)) return prims.result();
    // 4. Done when the closest candidate lies within this cell's range (a
    //    candidate beyond it may still be beaten in a later cell), or when
    //    the ray leaves its segment; leaving the grid is the index check
    //    below. Past the segment's end, not at it: far from the origin float
    //    t rounds whole cells to one value, and a cell whose exit read equal
    //    to the end stopped the walk at the first cell (hits beyond it are
    //    refused by the triangle tests anyway).
    if (prims.tmax() <= t_exit || t_exit > t_end) break;
    const int a = t_next[0] <= t_next[1] ? (t_next[0] <= t_next[2] ? 0 : 2) : (t_next[1] <= t_next[2] ? 1 : 2);
    idx[a] += step[a];
    if (step[a] == 0 || idx[a] < 0 || idx[a] >= res_[a]) break;
    if constexpr (kCollect) t_cell = t_next[a];
    t_next[a] = (plane(a, idx[a] + (step[a] > 0)) - ray.origin[a]) * ray.inv_dir[a];
  }
  return prims.result();
}

Hit Grid::closest_hit(const Ray& ray, const QueryOptions& qo, RayStats* stats, VisitTrace* trace) const {
  if (stats || trace) return traverse<true, false>(ray, qo, stats, trace);
  return traverse<false, false>(ray, qo, nullptr, nullptr);
}

bool Grid::any_hit(const Ray& ray, const QueryOptions& qo, RayStats* stats) const {
  if (stats) return traverse<true, true>(ray, qo, stats, nullptr).valid();
  return traverse<false, true>(ray, qo, nullptr, nullptr).valid();
}

}  // namespace accelviz
