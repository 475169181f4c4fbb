#include "core/accel/brute_force.h"
#include "core/util/timing.h"

#include <chrono>

namespace accelviz {

BruteForce::BruteForce(std::span<const Triangle> triangles, const BruteForceOptions& opts)
    : tris_(triangles), opts_(opts) {
  const auto t0 = std::chrono::steady_clock::now();
  if (opts_.bbox_early_out) {
    boxes_.reserve(tris_.size());
    for (const Triangle& t : tris_) boxes_.push_back(t.bounds());
  }
  stats_.build_ms = ms_since(t0);
  // The scene's triangles it reads count (not copied), as Embree's shared buffers do.
  stats_.memory_bytes = boxes_.size() * sizeof(Aabb) + tris_.size() * sizeof(Triangle);
  stats_.extra["memory_triangles"] = static_cast<double>(tris_.size() * sizeof(Triangle));
  if (!opts_.bbox_early_out) {
    stats_.node_count = 0;
    stats_.leaf_count = 1;
    stats_.sah_cost = static_cast<double>(tris_.size());  // every ray tests every primitive (C_isect = 1)
  } else {
    // A flat tree of one-triangle leaves: every ray tests every box (a node visit, C_trav = 1) and a
    // triangle where it enters its box (C_isect = 1, with the box's share of the root's area).
    Aabb root = Aabb::empty();
    for (const Aabb& b : boxes_) root.extend(b);
    double entered = 0.0;
    const double root_area = root.surface_area();
    for (const Aabb& b : boxes_) entered += root_area > 0.0 ? b.surface_area() / root_area : 1.0;
    stats_.node_count = tris_.size();
    stats_.leaf_count = tris_.size();
    stats_.max_depth = 1;
    stats_.avg_leaf_depth = 1.0;
    stats_.sah_cost = static_cast<double>(tris_.size()) + entered;
  }
}

Hit BruteForce::closest_hit(const Ray& ray, const QueryOptions& qo, RayStats* stats, VisitTrace* trace) const {
  const WatertightRay wr(ray.direction);
  Hit best;
  float tmax = ray.tmax;
  for (std::size_t i = 0; i < tris_.size(); ++i) {
    if (opts_.bbox_early_out) {
      SlabInterval iv;
      if (stats) ++stats->box_tests, ++stats->nodes_visited;  // a one-triangle leaf's box, as the trees count
      if (!intersect_slab(boxes_[i], ray.origin, ray.inv_dir, ray.tmin, tmax, iv)) continue;
    }
    if (stats) ++stats->prim_tests;
    Hit h;
    const bool hit = intersect_triangle(qo.triangle_test, ray, wr, tris_[i], ray.tmin, tmax, h);
    if (trace)
      trace->steps.push_back({hit ? VisitStep::Kind::prim_hit : VisitStep::Kind::prim_miss,
                              static_cast<std::uint32_t>(i), hit ? h.t : kInfinity, kInfinity});
    if (hit && h.t < best.t) {
      best = h;
      best.prim = static_cast<std::uint32_t>(i);
      tmax = h.t;
    }
  }
  if (best.valid()) best.ng = triangle_normal(tris_[best.prim]);
  return best;
}

bool BruteForce::any_hit(const Ray& ray, const QueryOptions& qo, RayStats* stats) const {
  const WatertightRay wr(ray.direction);
  for (std::size_t i = 0; i < tris_.size(); ++i) {
    if (opts_.bbox_early_out) {
      SlabInterval iv;
      if (stats) ++stats->box_tests, ++stats->nodes_visited;
      if (!intersect_slab(boxes_[i], ray, iv)) continue;
    }
    if (stats) ++stats->prim_tests;
    Hit h;
    if (intersect_triangle(qo.triangle_test, ray, wr, tris_[i], ray.tmin, ray.tmax, h)) return true;
  }
  return false;
}

}  // namespace accelviz
