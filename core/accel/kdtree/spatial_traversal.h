#pragma once
// Traversal pieces shared by the space-partitioning structures (K-D tree,
// uniform grid, octree, sparse voxels): how a ray segment divides at an
// axis-aligned plane, the per-ray mailbox, the exact record of tested
// primitives that the statistics path uses, the padding of cells, the
// record of the first box test, and the primitive tests of a cell or leaf.
//
// The common rule that makes all of them correct (pbrt's kd-tree, Havran's
// TA_rec): a primitive found in a cell or leaf is kept as a candidate even
// when its hit lies beyond that cell's exit, and it shrinks the ray's tmax;
// but the search only ends when the next cell's entry lies beyond the closest
// candidate. A primitive that straddles cells may be hit outside the cell it
// was tested in, with a nearer primitive still waiting in a later cell, so a
// hit beyond the current exit must not end the search. Keeping (rather than
// rejecting) such hits is also what makes mailboxing safe: a primitive is
// never tested twice, so its first result must not be thrown away.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <glm/glm.hpp>
#include <span>
#include <type_traits>
#include <unordered_set>

#include "core/accel/accel.h"
#include "core/geometry/triangle.h"
#include "core/math/ray.h"

namespace accelviz::spatial {

/// Cells are padded by this fraction of the structure's largest extent
/// before the triangle-box overlap test, so that a triangle within rounding
/// distance of a cell is referenced by it. The DDA and the plane tests decide
/// which cell a ray is in with float arithmetic whose error grows with the
/// distance from the origin (about 1e-7 of it); the padding covers origins
/// up to about a hundred scene extents away. Over-referencing costs a few
/// extra tests; under-referencing would lose hits.
inline constexpr float kCellPaddingRel = 1e-5f;

/// The padding for a structure over `bounds`: kCellPaddingRel of its largest
/// extent plus a few float ulps of its largest coordinate (a scene far from
/// the origin has coarse coordinates whatever its extent).
inline float cell_padding(const glm::vec3& lo, const glm::vec3& hi) {
  const glm::vec3 e = hi - lo;
  const float extent = std::max({e.x, e.y, e.z, 0.0f});
  const glm::vec3 m = glm::max(glm::abs(lo), glm::abs(hi));
  const float magnitude = std::max({m.x, m.y, m.z});
  return kCellPaddingRel * extent + 8.0f * 1.1920929e-7f * magnitude;
}

/// Relative slack when deciding whether a segment [t0, t1] reaches a plane
/// crossed at t: 8 ulps, several times the error of (plane - o) * inv_dir.
inline constexpr float kPlaneSlackRel = 8.0f * 1.1920929e-7f;

/// False for rays no structure should walk: a non-finite origin or a NaN
/// direction component (no triangle test can hit along them either).
inline bool is_traversable(const Ray& r) {
  return std::isfinite(r.origin.x) && std::isfinite(r.origin.y) && std::isfinite(r.origin.z) &&
         !std::isnan(r.direction.x) && !std::isnan(r.direction.y) && !std::isnan(r.direction.z) &&
         !std::isnan(r.tmin) && !std::isnan(r.tmax);
}

/// One part of a ray segment on one side of a plane.
struct SidePiece {
  std::uint8_t side;  ///< 0 = below the plane, 1 = above
  float t0, t1;       ///< the part of the segment on that side
  bool crossed;       ///< t0 is this plane's crossing (the ray enters the side through the plane)
};

/// Splits the segment [t0, t1] of a ray at the plane x_axis = plane, giving
/// the parts on each side in the order the ray visits them (1 or 2 pieces;
/// 0 only for NaN input). `o` and `inv_d` are the ray's origin and inverse
/// direction on that axis.
///  - Ray parallel to the plane (inv_d infinite, i.e. a ±0 direction
///    component or one so small its inverse overflows): the side is the
///    origin's. A ray lying in the plane visits both sides when
///    `in_plane_both` (the K-D tree and octree: a triangle touching the plane
///    from either side may be hit), else only the upper side (voxels, which
///    need one consistent answer with the dense reference).
///  - Otherwise the plane is crossed at t = (plane - o) * inv_d. The near side
///    is visited when t >= t0 - slack and the far side when t <= t1 + slack,
///    both inclusive, so a crossing exactly at t0 or t1 visits both sides
///    (the near one with an empty interval) and a primitive lying in the plane
///    is never skipped. slack = rel_slack·|t| absorbs rounding of t.
inline int split_at_plane(float o, float inv_d, float plane, float t0, float t1, float rel_slack, bool in_plane_both,
                          std::array<SidePiece, 2>& out, float* t_cross = nullptr) {
  if (std::isinf(inv_d)) {
    if (t_cross) *t_cross = -kInfinity;
    if (o < plane) {
      out[0] = {0, t0, t1, false};
      return 1;
    }
    if (o > plane || !in_plane_both) {
      out[0] = {1, t0, t1, false};
      return 1;
    }
    out[0] = {0, t0, t1, false};
    out[1] = {1, t0, t1, false};
    return 2;
  }
  const float t = (plane - o) * inv_d;
  if (t_cross) *t_cross = t;
  const std::uint8_t near_side = inv_d > 0.0f ? 0 : 1;
  const float slack = rel_slack * std::fabs(t);
  const bool visit_near = t >= t0 - slack;
  const bool visit_far = t <= t1 + slack;
  const float tc = std::clamp(t, t0, std::max(t0, t1));  // crossing clamped into the segment
  int n = 0;
  if (visit_near) out[n++] = {near_side, t0, tc, false};
  if (visit_far) out[n++] = {static_cast<std::uint8_t>(1 - near_side), tc, t1, t > t0};
  return n;
}

/// Mailboxing (Amanatides & Woo 1987; Havran's thesis 2000, §4.8): a small
/// per-ray cache of the primitive ids already tested, so that a primitive
/// referenced by several cells is tested once per ray. Hashed, 16 slots: a
/// collision merely evicts an entry and costs a repeated test, never a wrong
/// answer (see the file comment for why repeated tests are harmless).
class Mailbox {
 public:
  Mailbox() { ids_.fill(kInvalidId); }
  /// True when `id` was already tested by this ray; otherwise records it.
  bool seen(std::uint32_t id) {
    std::uint32_t& slot = ids_[(id * 0x9E3779B1u) >> 28];
    if (slot == id) return true;
    slot = id;
    return false;
  }

 private:
  std::array<std::uint32_t, 16> ids_;
};

/// Exact set of the primitives a ray has tested, kept only on the statistics
/// path to count RayStats::repeated_prim_tests (what straddling primitives
/// cost without, or past, the mailbox).
class TestedSet {
 public:
  /// Records `id`; true when it had been tested before.
  bool repeat(std::uint32_t id) { return !ids_.insert(id).second; }

 private:
  std::unordered_set<std::uint32_t> ids_;
};

/// What the fast path keeps instead of a TestedSet: nothing.
struct NoTestedSet {};

/// The tested-primitive set of a traversal: a TestedSet on the statistics
/// path (kCollect), an empty struct that compiles away otherwise.
template <bool kCollect>
using TestedSetFor = std::conditional_t<kCollect, TestedSet, NoTestedSet>;

/// The statistics path's record of a walk's first test (the structure's box
/// or domain, node 0): one box test, and on a miss node 0 missed over
/// [t0, t1]. Compiles away without kCollect.
template <bool kCollect>
inline void record_root_test(bool hit, float t0, float t1, RayStats* stats, VisitTrace* trace) {
  if constexpr (kCollect) {
    if (stats) ++stats->box_tests;
    if (!hit) {
      if (stats) ++stats->nodes_missed;
      if (trace) trace->steps.push_back({VisitStep::Kind::node_missed, 0, t0, t1});
    }
  }
}

/// The primitive tests of the K-D tree's leaves, the grid's cells and the
/// octree's leaves, for one ray: each referenced primitive is tested against
/// [tmin, closest candidate so far] (mailboxed when the structure asks), a
/// hit becomes the candidate whatever cell it lies in (the file comment's
/// rule), and the statistics path counts the tests, the repeated ones and
/// traces each outcome.
template <bool kCollect, bool kAnyHit>
class CellPrimTests {
 public:
  CellPrimTests(const Ray& ray, TriangleTest test, bool mailboxing, std::span<const Triangle> tris, RayStats* stats,
                VisitTrace* trace)
      : ray_(ray),
        wr_(ray.direction),
        tris_(tris),
        test_(test),
        mailboxing_(mailboxing),
        tmax_(ray.tmax),
        stats_(stats),
        trace_(trace) {}

  /// Tests the primitives ids[0 .. count). True when the walk is over: an
  /// any-hit query found its hit.
  bool test(const std::uint32_t* ids, std::uint32_t count) {
    for (std::uint32_t k = 0; k < count; ++k) {
      const std::uint32_t id = ids[k];
      if (mailboxing_ && mailbox_.seen(id)) continue;
      if constexpr (kCollect) {
        if (stats_) {
          ++stats_->prim_tests;
          if (tested_.repeat(id)) ++stats_->repeated_prim_tests;
        }
      }
      Hit h;
      const bool hit = intersect_triangle(test_, ray_, wr_, tris_[id], ray_.tmin, tmax_, h);
      if constexpr (kCollect) {
        if (trace_)
          trace_->steps.push_back(
              {hit ? VisitStep::Kind::prim_hit : VisitStep::Kind::prim_miss, id, hit ? h.t : kInfinity, kInfinity});
      }
      if (hit) {
        best_ = h;
        best_.prim = id;
        if constexpr (kAnyHit) return true;
        tmax_ = h.t;
      }
    }
    return false;
  }

  /// The closest candidate's distance (the ray's tmax before any hit).
  float tmax() const { return tmax_; }

  /// The hit: the closest one with its geometric normal, or the any-hit
  /// query's first (callers ask only whether there is one: no normal).
  Hit result() const {
    Hit h = best_;
    if constexpr (!kAnyHit) {
      if (h.valid()) h.ng = triangle_normal(tris_[h.prim]);
    }
    return h;
  }

 private:
  const Ray& ray_;
  const WatertightRay wr_;
  std::span<const Triangle> tris_;
  TriangleTest test_;
  bool mailboxing_;
  float tmax_;
  Hit best_;
  Mailbox mailbox_;
  [[no_unique_address]] TestedSetFor<kCollect> tested_;
  RayStats* stats_;  ///< read only on the statistics path (kCollect)
  VisitTrace* trace_;
};

}  // namespace accelviz::spatial
