#include "core/analysis/insight/traversal_modes.h"

#include <vector>

#include "core/query/batch.h"

namespace accelviz {

std::string_view mode_name(TraversalMode m) {
  switch (m) {
    case TraversalMode::unordered:
      return "unordered";
    case TraversalMode::front_to_back:
      return "front-to-back";
    case TraversalMode::back_to_front:
      return "back-to-front";
    case TraversalMode::xray:
      return "x-ray";
    case TraversalMode::any_hit:
      return "any-hit";
  }
  return "?";
}

QueryOptions query_for_mode(const QueryOptions& base, TraversalMode m) {
  QueryOptions q = base;
  q.ordered = m != TraversalMode::unordered;
  q.back_to_front = m == TraversalMode::back_to_front;
  q.xray = m == TraversalMode::xray;
  return q;
}

ModeTotals measure_mode(const Accelerator& accel, std::span<const Ray> rays, const QueryOptions& base, TraversalMode m,
                        unsigned threads) {
  ModeTotals t;
  t.mode = m;
  t.rays = rays.size();
  std::vector<RayStats> stats(rays.size());
  const QueryOptions q = query_for_mode(base, m);
  if (m == TraversalMode::any_hit) {
    std::vector<std::uint8_t> occluded(rays.size());
    trace_any(accel, rays, occluded, q, threads, stats);
    for (const std::uint8_t o : occluded) t.hits += o;
  } else {
    std::vector<Hit> hits(rays.size());
    trace_closest(accel, rays, hits, q, threads, stats);
    for (const Hit& h : hits) t.hits += h.valid() ? 1 : 0;
  }
  for (const RayStats& s : stats) {
    t.sum += s;
    t.nodes_visited += s.nodes_visited;
    t.nodes_missed += s.nodes_missed;
    t.nodes_culled += s.nodes_culled;
    t.prim_tests += s.prim_tests;
    t.leaves_skipped += s.leaves_skipped;
  }
  return t;
}

}  // namespace accelviz
