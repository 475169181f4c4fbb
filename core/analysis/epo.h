#pragma once
// Effective primitive overlap (Aila, Karras, Laine, "On Quality Metrics of
// Bounding Volume Hierarchies", HPG 2013). SAH assumes that a ray entering a
// node meets only that node's own geometry; in a BVH, boxes overlap geometry
// of other subtrees, and a ray hitting such geometry must traverse every
// node whose box contains it. EPO charges each node n for the area of the
// scene's surface that lies inside n's box but belongs to primitives outside
// n's subtree:
//
//   EPO = Σ_n C(n) · A((S \ Q(n)) ∩ box(n)) / A(S)
//
// with S all triangles, Q(n) those in n's subtree, A surface area (triangles
// clipped to the box), C(n) = C_trav for inner nodes and C_isect·N(n) for
// leaves. The paper found it predicts ray-tracing time better than SAH alone
// for trees with much overlap.
#include "core/accel/bvh/bvh.h"
#include "core/geometry/triangle.h"
#include "core/math/aabb.h"

#include <cstdint>
#include <span>

namespace accelviz {

/// Area of the part of `tri` inside `box` (Sutherland-Hodgman clipping
/// against the six slab planes, in double precision).
double clipped_triangle_area(const Triangle& tri, const Aabb& box);

/// EPO of a BVH over `triangles` in scene order (prim_indices maps leaf
/// positions to scene ids). Requires each subtree's primitives to be
/// contiguous in prim_indices, as every top-down build leaves them
/// (std::invalid_argument otherwise). 0 when the scene has no area.
/// Work is spread over `threads` (0 = all); the result does not depend on it.
///
/// Its cost grows with the overlap: on degenerate scenes (every centroid
/// equal) it is quadratic and takes seconds where the build took
/// milliseconds. `progress`, when given, is called now and then (from one
/// working thread at a time) with the fraction of triangles done; returning
/// false stops it, and bvh_epo throws BuildCancelled (so quitting the app or
/// opening another scene does not wait for it).
double bvh_epo(std::span<const BvhNode> nodes, std::span<const std::uint32_t> prim_indices,
               std::span<const Triangle> triangles, double cost_traversal, double cost_intersect, unsigned threads = 0,
               const ProgressCallback& progress = {});

/// Same, with the triangles already in leaf order (leaf_triangles[k] is the
/// primitive at leaf position k), as class Bvh keeps them.
double bvh_epo_leaf_order(std::span<const BvhNode> nodes, std::span<const Triangle> leaf_triangles,
                          double cost_traversal, double cost_intersect, unsigned threads = 0,
                          const ProgressCallback& progress = {});

}  // namespace accelviz
