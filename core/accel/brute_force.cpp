#include "core/accel/brute_force.h"

#include <chrono>
#include <type_traits>

#include "core/accel/bvh/bvh_triangle.h"
#include "core/util/timing.h"

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

namespace {

/// closest_hit's loop, generic in the triangle test (`test(tri, tmax, hit)`; with_triangle_test picks
/// it). kCount: stats and trace may be set; without it they are never read.
template <bool kCount, class Test>
Hit closest_loop(std::span<const Triangle> tris, const std::vector<Aabb>& boxes, bool bbox_early_out, const Ray& ray,
                 const Test& test, RayStats* stats, VisitTrace* trace) {
  Hit best;
  float tmax = ray.tmax;
  for (std::size_t i = 0; i < tris.size(); ++i) {
    if (bbox_early_out) {
      SlabInterval iv;
      if constexpr (kCount)
        if (stats) ++stats->box_tests, ++stats->nodes_visited;  // a one-triangle leaf's box, as the trees count
      if (!intersect_slab(boxes[i], ray.origin, ray.inv_dir, ray.tmin, tmax, iv)) continue;
    }
    if constexpr (kCount)
      if (stats) ++stats->prim_tests;
    Hit h;
    const bool hit = test(tris[i], tmax, h);
    if constexpr (kCount)
      if (trace)
        trace->steps.push_back({hit ? VisitStep::Kind::prim_hit : VisitStep::Kind::prim_miss,
                                static_cast<std::uint32_t>(i), hit ? h.t : kInfinity, kInfinity});
    if (hit && h.t < best.t) {
      best = h;
      best.prim = static_cast<std::uint32_t>(i);
      tmax = h.t;
    }
  }
  if (best.valid()) best.ng = triangle_normal(tris[best.prim]);
  return best;
}

/// any_hit's loop, as closest_loop.
template <bool kCount, class Test>
bool any_loop(std::span<const Triangle> tris, const std::vector<Aabb>& boxes, bool bbox_early_out, const Ray& ray,
              const Test& test, RayStats* stats) {
  for (std::size_t i = 0; i < tris.size(); ++i) {
    if (bbox_early_out) {
      SlabInterval iv;
      if constexpr (kCount)
        if (stats) ++stats->box_tests, ++stats->nodes_visited;
      if (!intersect_slab(boxes[i], ray, iv)) continue;
    }
    if constexpr (kCount)
      if (stats) ++stats->prim_tests;
    Hit h;
    if (test(tris[i], ray.tmax, h)) return true;
  }
  return false;
}

/// Runs `loop(count, test)` with the ray's triangle test `test(tri, tmax, hit)`. With statistics or a
/// trace (`count` is std::true_type) the out-of-line dispatch, as the trees' counting walks; otherwise
/// the BVH walks' inline tests, bit for bit the same results (core/accel/bvh/bvh_triangle.h; verify
/// and the brute-force heatmaps spend their time here).
template <class Loop>
auto with_triangle_test(const Ray& ray, TriangleTest which, bool counting, const Loop& loop) {
  if (counting) {
    const WatertightRay wr(ray.direction);
    return loop(std::true_type{}, [&](const Triangle& tri, float tmax, Hit& h) {
      return intersect_triangle(which, ray, wr, tri, ray.tmin, tmax, h);
    });
  }
  const bvh_detail::InlineWatertightRay ir(ray);  // read by the watertight test only
  if (which == TriangleTest::watertight)
    return loop(std::false_type{}, [&](const Triangle& tri, float tmax, Hit& h) {
      return bvh_detail::test_triangle<TriangleTest::watertight>(ray, ir, tri, ray.tmin, tmax, h);
    });
  return loop(std::false_type{}, [&](const Triangle& tri, float tmax, Hit& h) {
    return bvh_detail::test_triangle<TriangleTest::moller_trumbore>(ray, ir, tri, ray.tmin, tmax, h);
  });
}

}  // namespace

Hit BruteForce::closest_hit(const Ray& ray, const QueryOptions& qo, RayStats* stats, VisitTrace* trace) const {
  return with_triangle_test(ray, qo.triangle_test, stats || trace, [&](auto count, const auto& test) {
    return closest_loop<decltype(count)::value>(tris_, boxes_, opts_.bbox_early_out, ray, test, stats, trace);
  });
}

bool BruteForce::any_hit(const Ray& ray, const QueryOptions& qo, RayStats* stats) const {
  return with_triangle_test(ray, qo.triangle_test, stats != nullptr, [&](auto count, const auto& test) {
    return any_loop<decltype(count)::value>(tris_, boxes_, opts_.bbox_early_out, ray, test, stats);
  });
}

}  // namespace accelviz
